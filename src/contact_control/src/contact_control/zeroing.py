"""Zeroing the sensor at start-up over a steady window, not on one sample (see the README, Zeroing).

One sample carries the sensor's noise into the bias for good (0.4 N on an estimated wrench), and a touch at
that instant becomes a bias that drives a follower the other way once the touch ends. The window's bias
estimates must stay within a peak-to-peak spread: a change (a touch starting or ending, a jolt) restarts it.
A contact held perfectly still through the whole window cannot be told from a sensor offset.

A noisy sensor (a wrench estimated from joint currents: 3.6 N std) spreads by more than any fixed limit a
clean one needs, so the limit also scales with the noise: the first `probe` samples of a window are not
checked one by one; their robust std (median absolute deviation, which a touch in under half of them does
not inflate) sets the limit to max(configured, `spread_sigmas` stds), and the probe itself must pass it.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

__all__ = ["SteadyZero"]


class SteadyZero:
    """The mean of the bias estimates (sensor frame, tool weight out) over `window` [s] in which no force
    component moved more than `max_force_spread` [N] and no torque more than `max_torque_spread` [Nm], or
    `spread_sigmas` times the noise's std when larger (the std given as `noise`, else measured over the
    window's first `min_samples`; 0: fixed limits)."""

    def __init__(self, window: float, max_force_spread: float, max_torque_spread: float,
                 min_samples: int = 1, spread_sigmas: float = 0.0,
                 noise: Sequence[float] | None = None) -> None:
        self.window = window
        self.min_samples = max(1, min_samples)  # the noise floor needs a few samples at a slow sensor's rate
        self._configured = (max_force_spread,) * 3 + (max_torque_spread,) * 3
        self._sigmas = spread_sigmas
        self._noise = None if noise is None or spread_sigmas <= 0.0 else tuple(noise)
        # Samples checked together once the probe is full (no probe: the limits are known from the start).
        self._probe = self.min_samples if spread_sigmas > 0.0 and noise is None and min_samples > 2 else 0
        self._probed: list[Sequence[float]] = []
        self._limits = self._scaled(self._noise) if self._noise is not None else self._configured
        self._t0: float | None = None
        self._sum = [0.0] * 6
        self._squares = [0.0] * 6
        self._lagged = [0.0] * 6  # sum of x_k x_(k-1): the lag-1 autocorrelation (how slow the noise is)
        self._previous = [0.0] * 6
        self._origin = [0.0] * 6
        self._shifted = [0.0] * 6
        self._low = [0.0] * 6
        self._high = [0.0] * 6
        self._count = 0
        self.duration = 0.0  # [s] of the completed window
        #: Why it is still waiting, in words (for ~status).
        self.note = "zeroing the sensor: waiting for the first wrench"

    def _scaled(self, std: Sequence[float]) -> tuple[float, ...]:
        return tuple(max(limit, self._sigmas * s) for limit, s in zip(self._configured, std, strict=True))

    @property
    def limits(self) -> tuple[float, ...]:
        """The peak-to-peak limits per axis in force now [N, Nm]."""
        return self._limits

    def _restart(self, estimate: Sequence[float], t: float) -> None:
        self._t0 = t
        if self._probe:
            self._probed = [estimate]
        self._sum = list(estimate)
        self._origin = list(estimate)  # the statistics use values relative to the first: no cancellation
        self._shifted = [0.0] * 6
        self._squares = [0.0] * 6
        self._lagged = [0.0] * 6
        self._previous = [0.0] * 6
        self._low = list(estimate)
        self._high = list(estimate)
        self._count = 1

    def add(self, estimate: Sequence[float], t: float) -> list[float] | None:
        """One bias estimate at `t` [s]; the bias once the window is complete, else None (see `note`)."""
        t0 = self._t0
        if t0 is None or t < t0:
            self._restart(estimate, t)
            t0 = t
        else:
            low, high = self._low, self._high
            for i, value in enumerate(estimate):
                if value < low[i]:
                    low[i] = value
                elif value > high[i]:
                    high[i] = value
            probing = len(self._probed) < self._probe
            if probing:
                self._probed.append(estimate)
                if len(self._probed) == self._probe:  # the noise is known: the limits follow it
                    self._limits = self._scaled(_robust_std(self._probed))
                    probing = False
            worst = max(range(6), key=lambda i: (high[i] - low[i]) / self._limits[i])
            spread = high[worst] - low[worst]
            if not probing and spread > self._limits[worst]:
                unit, name = ("N", "force") if worst < 3 else ("Nm", "torque")
                limit = self._limits[worst]
                why = (f"tare_max_{name}_spread" if limit <= self._configured[worst]
                       else f"{self._sigmas:g} noise stds")
                self.note = (
                    f"zeroing the sensor: the {name} changed by {spread:.2f} {unit} within "
                    f"{t - t0:.2f} s (limit {why} {limit:.3g} {unit}): keep the tool free and still"
                )
                self._restart(estimate, t)
                return None
            previous, origin = self._previous, self._origin
            for i, value in enumerate(estimate):
                self._sum[i] += value
                x = value - origin[i]
                self._shifted[i] += x
                self._squares[i] += x * x
                self._lagged[i] += x * previous[i]
                previous[i] = x
            self._count += 1
        if t - t0 < self.window or self._count < self.min_samples:
            if self._count == 1:
                self.note = f"zeroing the sensor over {self.window:g} s: keep the tool free and still"
            return None
        self.duration = t - t0
        return [total / self._count for total in self._sum]

    @property
    def count(self) -> int:
        """Samples in the current (or completed) window."""
        return self._count

    def std(self) -> list[float]:
        """Standard deviation per axis over the window so far (sample std; 0 with one sample)."""
        n = self._count
        if n < 2:
            return [0.0] * 6
        return [math.sqrt(max(0.0, (sq - s * s / n) / (n - 1)))
                for s, sq in zip(self._shifted, self._squares, strict=True)]

    def lag1(self) -> list[float]:
        """Lag-1 autocorrelation per axis over the window (0: white noise; near 1: a slow drift)."""
        n = self._count
        if n < 3:
            return [0.0] * 6
        out = []
        for s, sq, lagged in zip(self._shifted, self._squares, self._lagged, strict=True):
            mean = s / n
            var = sq / n - mean * mean
            out.append(max(-1.0, min(1.0, (lagged / (n - 1) - mean * mean) / var)) if var > 1e-18 else 0.0)
        return out


def _robust_std(samples: Sequence[Sequence[float]]) -> list[float]:
    """Per axis, 1.4826 x the median absolute deviation: the std of Gaussian noise, not inflated by a step
    in under half of the samples."""
    x = np.asarray(samples, dtype=float)
    return list(1.4826 * np.median(np.abs(x - np.median(x, axis=0)), axis=0))
