"""The sensor's real sample period, measured from the wrenches themselves.

Real sensors publish at their own rate (an arm's built-in sensor at 500 Hz, a model-based estimate at its
controller's publish rate, 30 Hz by default or 92 Hz in one recording, a separate F/T box at 125-7000 Hz),
which is rarely the `lp_filter_delta_t` somebody typed. A filter designed for the wrong period has the wrong
cutoff (the configured 5 Hz became 0.92 Hz on 92 Hz data), and a fixed stale timeout is either shorter than
one period of a slow sensor or far too long for a fast one (the package README has the numbers). The period
is the mean interval over a window of samples: a publisher that sends in bursts (a starved process, stamping
at publish time) still averages its true rate, and a late sample's short next interval cancels its long one
(the median of the intervals read 168-370 Hz from the simulated 500 Hz sensor under CI's load, and each
reading redesigned the filter). A new rate is taken when two windows in a row agree on it, so one window
with a stall in it changes nothing. Gaps longer than `MAX_INTERVAL` (dropouts) are left out.
"""

from __future__ import annotations

import math

__all__ = ["MAX_INTERVAL", "SamplePeriod"]

MAX_INTERVAL = 0.5  # [s] an interval longer than this is a dropout, not the sensor's period
STEADY = 0.1  # two windows whose means differ by less than this fraction agree on the rate


class SamplePeriod:
    """Mean sample interval over windows of `window` intervals, taken when two windows in a row agree (the
    first window's at once); updated once per window (cheap per sample).

    Args:
        window: Intervals per estimate.
    """

    def __init__(self, window: int = 32) -> None:
        if window < 3:
            raise ValueError("window must hold at least 3 intervals")
        self._window = window
        self._sum = 0.0
        self._count = 0
        self._candidate: float | None = None
        self._last = math.nan
        self.period: float | None = None  # [s] the latest estimate; None until one window is full

    def add(self, t: float) -> bool:
        """Records a sample at time `t` [s] (its stamp, else its receive time); True when `period` changed."""
        last, self._last = self._last, t
        dt = t - last
        if not 0.0 < dt <= MAX_INTERVAL:  # the first sample (NaN), a repeat, a clock jump, a dropout
            return False
        self._sum += dt
        self._count += 1
        if self._count < self._window:
            return False
        mean = self._sum / self._count
        self._sum, self._count = 0.0, 0
        seen, self._candidate = self._candidate, mean
        if self.period is not None and (seen is None or abs(mean - seen) > STEADY * seen):
            return False  # one window's rate (a stall, a burst): kept only if the next window agrees
        changed = mean != self.period
        self.period = mean
        return changed

    def reset(self) -> None:
        """Forgets the last sample time (after a clock jump); keeps the estimate."""
        self._last = math.nan
        self._sum, self._count = 0.0, 0
        self._candidate = None
