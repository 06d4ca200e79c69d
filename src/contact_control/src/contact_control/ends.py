"""A move's axis end conditions over its cycles: force limits, max travel and force jumps, and the reason an
end gives in words (no ROS here; the package README, *Moves and how they end*).

A force limit counts only when armed, `force_limit_arm_time` after the axes started from rest (the tool's own
inertia while speeding up reads as force on a wrist sensor: 1 kg at 0.5 m/s^2 is 0.5 N), and only after
`force_limit_samples` wrenches in a row over it (one spike is not a contact).
"""

from __future__ import annotations

import math
from collections.abc import Sequence

from contact_control.axes import AXES, END_NAMES, End
from contact_control.law_set import LawSet
from contact_control.laws import AxisLaw, ForceWindow, check_end

__all__ = ["EndChecks", "end_reason"]


class EndChecks:
    """The counters and windows behind the end conditions of the six axes.

    Args:
        diff: per axis, the largest force change within `window` [N, Nm] (0: not checked).
        window: the force-jump window [s].
        arm_time: force limits count from this long after a start from rest [s] (0: at once).
        limit_samples: wrenches in a row over a force limit that end the move.
    """

    def __init__(self, diff: Sequence[float], window: float, arm_time: float, limit_samples: int) -> None:
        self.diff = tuple(diff)
        self._windows = [ForceWindow(window) for _ in range(6)]
        self._arm_time = arm_time
        self._limit_samples = limit_samples
        self._over = [0] * 6  # per axis: wrenches in a row over its force limit
        self.armed = [True] * 6
        self._from_rest: float | None = None  # when the axes last started from rest

    def restart(self, t: float | None) -> None:
        """A new move from rest at `t`: nothing counted, force limits disarmed for `arm_time`."""
        self.clear_windows()
        self.clear_over()
        self.armed = [self._arm_time <= 0.0] * 6
        self._from_rest = t

    def restart_axis(self, axis: int) -> None:
        """An axis whose law changed starts from rest (then `started`)."""
        self._windows[axis].clear()
        self.armed[axis] = self._arm_time <= 0.0

    def started(self, t: float | None) -> None:
        """Axes started from rest at `t`: the arming time counts from there while any is disarmed."""
        if not all(self.armed):
            self._from_rest = t

    def clear_windows(self) -> None:
        for window in self._windows:
            window.clear()

    def clear_over(self) -> None:
        self._over = [0] * 6

    def held(self, t: float) -> None:
        """The output stopped at `t`: the speed-up that follows is a new start."""
        if self._arm_time > 0.0:
            self.armed = [False] * 6
            self._from_rest = t

    def arm(self, t: float) -> None:
        """Force limits count from `arm_time` after the axes started from rest."""
        if all(self.armed):
            return
        if self._from_rest is None:
            self._from_rest = t
        if t - self._from_rest >= self._arm_time:
            self.armed = [True] * 6

    def check(self, t: float, laws: LawSet, w: Sequence[float], travel: Sequence[float]) -> tuple[int, int]:
        """(axis, END_*) of the first active axis that meets a force limit, its max travel or a force jump
        this cycle; (-1, END_NONE) when none does."""
        armed, over, is_path = self.armed, self._over, laws.is_path
        for i in laws.active:
            law, moved = laws.laws[i], 0.0 if is_path[i] else travel[i]
            end = check_end(law, w[i] if armed[i] else 0.0, moved)
            if end == End.FT_VIOLATION:
                over[i] += 1
                if over[i] < self._limit_samples:  # one spike over the limit is not a contact
                    end = check_end(law, 0.0, moved)
            elif over[i]:
                over[i] = 0
            if end:
                return i, end
        for i in laws.diff_axes:
            if self._windows[i].add(t, w[i]) > self.diff[i]:
                return i, End.DIFF_VIOLATION
        return -1, End.NONE


def end_reason(axis: int, condition: int, law: AxisLaw, *, force: float, travel: float, path_error: float,
               path_age: float, path_timeout: float, diff: float) -> str:
    """The end message: `axis x: force/torque limit: |20.3| reached the limit 20.0`."""
    if condition == End.FT_VIOLATION:
        why = f"|{force:.3g}| reached the limit {law.force_limit}"
    elif condition == End.PATH_LOST:
        why = ("no ~path_reference received" if path_age == math.inf else
               f"no ~path_reference for {path_age:.2f} s (path_reference_timeout {path_timeout:g} s)")
    elif condition == End.PATH_ERROR:
        unit = "rad" if axis >= 3 else "m"
        why = f"|{path_error:.4g}| {unit} from the path reached max_travel {law.max_travel:g}"
    elif condition == End.MAX_TRAVEL:
        why = f"travel |{travel:.4g}| reached the max path deviation {law.max_travel}"
    else:
        why = f"force changed by more than {diff} within the window"
    return f"axis {AXES[axis]}: {END_NAMES[condition]}: {why}"
