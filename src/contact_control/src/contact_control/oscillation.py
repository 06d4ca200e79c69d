"""The oscillation watchdog (pure; see the README's *Oscillation watchdog*): an axis whose commanded velocity
reverses `reversals` times within `window` seconds, each time beyond its minimum velocity, oscillates: the
force it reacts to is its own motion's (a tool's inertia on a slow sensor, a lagging arm), not a push. The
controller then halves that axis's gain once, and stops the move if it goes on."""

from __future__ import annotations

from collections import deque
from dataclasses import replace

from contact_control.axes import LAW_COMPLIANT_MOVE, LAW_FOLLOWER, LAW_FORCE_TRACKING, LAW_SPRING
from contact_control.laws import AxisLaw

__all__ = ["OscillationWatch", "halved"]


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
    return None
