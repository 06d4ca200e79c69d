"""The oscillation watchdog (pure; see the README's *Oscillation watchdog*): an axis whose commanded velocity
reverses `reversals` times within `window` seconds, each time beyond its minimum velocity, oscillates: the
force it reacts to is its own motion's (a tool's inertia on a slow sensor, a lagging arm), not a push. The
controller then halves that axis's gain once, and stops the move if it goes on."""

from __future__ import annotations

from collections import deque
from collections.abc import Sequence
from dataclasses import replace

from contact_control.axes import (
    AXES,
    LAW_COMPLIANT_MOVE,
    LAW_FOLLOWER,
    LAW_FORCE_TRACKING,
    LAW_NONE,
    LAW_NORMAL,
    LAW_SPRING,
)
from contact_control.laws import AxisLaw
from contact_control.noise_floor import NoiseFloor
from contact_control.params import AxisTuning

__all__ = ["OscillationGuard", "OscillationWatch", "halved"]

#: Filtered noise stds of force a velocity reversal must exceed to count for the watchdog (noise
#: crosses 3 stds about once in 20 independent samples: ~2 s of a 5 Hz filter's output).
WATCH_NOISE_SIGMAS = 3.0


class OscillationWatch:
    """Counts velocity reversals per axis over a sliding window."""

    def __init__(self, reversals: int, window: float) -> None:
        self.reversals, self.window = reversals, window
        self._sign = [0.0] * 6
        self._times: list[deque[float]] = [deque() for _ in range(6)]

    def clear(self, axis: int | None = None) -> None:
        for i in range(6) if axis is None else (axis,):
            self._sign[i] = 0.0
            self._times[i].clear()

    def add(self, axis: int, t: float, v: float, floor: float) -> bool:
        """One commanded velocity of `axis` at `t`; True when it has reversed `reversals` times in `window`
        (velocities within `floor` of zero count as neither direction)."""
        if -floor <= v <= floor:
            return False
        sign = 1.0 if v > 0.0 else -1.0
        last, self._sign[axis] = self._sign[axis], sign
        if last == 0.0 or last == sign:
            return False
        times = self._times[axis]
        times.append(t)
        while times and times[0] < t - self.window:
            times.popleft()
        return len(times) >= self.reversals


def halved(law: AxisLaw) -> AxisLaw | None:
    """The law with half its loop gain (twice the damping; a spring's stiffness halved too), None if it has no
    force gain to lower (a compliant move without damping)."""
    if law.law in (LAW_FOLLOWER, LAW_FORCE_TRACKING) or (law.law == LAW_COMPLIANT_MOVE and law.damping > 0.0):
        return replace(law, damping=2.0 * law.damping)
    if law.law == LAW_SPRING:
        return replace(law, damping=2.0 * law.damping, stiffness=0.5 * law.stiffness)
    if law.law == LAW_NORMAL:  # its gain is k alone
        return replace(law, stiffness=0.5 * law.stiffness)
    return None


class OscillationGuard:
    """The watchdog over a move's axes: which velocity counts as a reversal, and what to do about one (halve
    the gain once, then stop)."""

    def __init__(self, reversals: int, window: float, tuning: Sequence[AxisTuning]) -> None:
        self.watch = OscillationWatch(reversals, window)
        self._halved = [False] * 6  # per axis: its gain was halved in this move
        self._floor = [t.min_velocity for t in tuning]
        self._seen: list[tuple[int, AxisLaw | None, str]] = []

    def clear(self) -> None:
        """A new request: nothing counted, no gain halved."""
        self.watch.clear()
        self._halved = [False] * 6

    def set_floor(self, tuning: Sequence[AxisTuning], laws: Sequence[AxisLaw],
                  noise: NoiseFloor | None) -> None:
        """The velocity floor per axis: the minimum velocity, or the swing the sensor's noise alone gives a
        law (WATCH_NOISE_SIGMAS filtered stds / b) when larger: held against a push, a law's force error
        crosses zero with the noise and a 3.6 N estimate reversed a spring's velocity 6 times in 2 s with
        nothing oscillating."""
        self._floor = [t.min_velocity for t in tuning]
        if noise is None:
            return
        for i, law in enumerate(laws):
            if law.law != LAW_NONE and law.damping > 0.0:
                std = noise.force if i < 3 else noise.torque
                self._floor[i] = max(self._floor[i], WATCH_NOISE_SIGMAS * std / law.damping)

    def check(self, t: float, velocity: Sequence[float], axes: Sequence[int], laws: Sequence[AxisLaw]
              ) -> list[tuple[int, AxisLaw | None, str]]:
        """The velocities commanded at `t` on `axes` under `laws`: for each axis that oscillates, (the axis,
        its law with the gain halved or None to stop the move, what was seen in words); the check ends at a
        stop. Usually empty (the same list, not to be kept)."""
        seen = self._seen
        seen.clear()
        add, floor = self.watch.add, self._floor
        for i in axes:
            if not add(i, t, velocity[i], floor[i]):
                continue
            law = laws[i]
            what = (f"axis {AXES[i]}: its velocity reversed {self.watch.reversals} times within "
                    f"{self.watch.window:g} s (oscillation_reversals)")
            lower = None if self._halved[i] else halved(law)
            self.watch.clear(i)
            if lower is None:
                seen.append((i, None, f"{what}: stopped, the gain was already lowered"))
                break
            self._halved[i] = True
            k = f"k {law.stiffness:g} -> {lower.stiffness:g}"
            gains = (k if law.law == LAW_NORMAL else f"b {law.damping:g} -> {lower.damping:g}"
                     + (f", {k}" if law.law == LAW_SPRING else ""))
            seen.append((i, lower, f"{what}: gain halved ({gains})"))
        return seen
