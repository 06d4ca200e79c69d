"""A program's replay timing planned against the arm's limits (no ROS): where the requested speed would
ask more velocity or acceleration of an axis than contact_control gives, those segments are stretched in
time, so the reference never runs away from the arm (it keeps the path; only the timing gives).

The reference is piecewise linear between waypoints: its velocity is constant on a segment and changes at
each waypoint, over half of the two segments around it (of a moving one only: a pause spreads nothing; the
replay's fed-forward velocity ramps over `replay_smoothing` there). Stretching a segment by c divides its
velocity by c and the accelerations around it by about c^2. Per axis, as contact_control limits them:
speeding up at most `acceleration`, slowing down at most `deceleration`, speeds at most `velocity` (linear,
then angular).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from compliant_common.typedefs import FloatArray

__all__ = ["Limits", "replay_times"]

_PASSES = 400  # stretching one segment may ask its neighbours for more; the passes settle it


@dataclass(frozen=True)
class Limits:
    """Per-axis limits of the arm's Cartesian motion (contact_control's), linear [m/s, m/s^2] then angular
    [rad/s, rad/s^2]; `inf` (the default) is no limit."""

    velocity: float = math.inf
    acceleration: float = math.inf
    deceleration: float = math.inf
    angular_velocity: float = math.inf
    angular_acceleration: float = math.inf
    angular_deceleration: float = math.inf

    def scaled(self, fraction: float) -> Limits:
        """These limits times `fraction` (a margin for the feedback that corrects the path)."""
        return Limits(*(fraction * v for v in (self.velocity, self.acceleration, self.deceleration,
                                                self.angular_velocity, self.angular_acceleration,
                                                self.angular_deceleration)))


def _change_ok(before: FloatArray, after: FloatArray, over: float, accel: FloatArray,
               decel: FloatArray) -> float:
    """The factor (>= 1) by which the time `over` must grow for the velocity change per axis to stay within
    the limits: speeding up (|after| > |before| on the same side) by accel, otherwise decel."""
    need = 1.0
    for k in range(6):
        dv = abs(after[k] - before[k])
        if dv <= 0.0:
            continue
        up = abs(after[k]) > abs(before[k]) and after[k] * before[k] >= 0.0
        limit = accel[k] if up else decel[k]
        if over <= 0.0:
            return math.inf
        # A uniform stretch c of the time divides velocities by c and the time they change over grows by c.
        need = max(need, math.sqrt(dv / (over * limit)))
    return need


def replay_times(times: FloatArray, deltas: FloatArray, speed: float, limits: Limits) -> FloatArray:
    """Replay time [s] at each waypoint: the program's `times` divided by `speed`, segments stretched where
    their velocity or the change of velocity at their ends (from and to rest at the ends) exceeds `limits`.

    Args:
        times: the waypoints' program times (n,), increasing.
        deltas: each segment's motion (n - 1, 6): position change [m] and rotation vector [rad].
        speed: the requested speed factor (> 0).
        limits: the arm's.
    """
    durations = np.diff(np.asarray(times, dtype=float)) / speed
    n = len(durations)
    if n == 0:
        return np.zeros(1)
    vmax = np.array([limits.velocity] * 3 + [limits.angular_velocity] * 3)
    accel = np.array([limits.acceleration] * 3 + [limits.angular_acceleration] * 3)
    decel = np.array([limits.deceleration] * 3 + [limits.angular_deceleration] * 3)
    stretch = np.ones(n)
    # A segment that does not move (a pause) spreads no change of velocity: a step from a coasting segment
    # into a pause happens within the coasting one (the simulated UR3 overshot a corner by 9 mm at 2 x when
    # the pause counted).
    moving = (durations > 0.0) & (np.abs(deltas).max(axis=1) > 1e-9)
    with np.errstate(divide="ignore", invalid="ignore"):
        fast = np.where(moving[:, None], np.abs(deltas) / (durations[:, None] * vmax), 0.0)
    stretch = np.maximum(stretch, np.nan_to_num(fast.max(axis=1), nan=1.0, posinf=1.0))
    rest = np.zeros(6)
    for _ in range(_PASSES):
        changed = False
        d = durations * stretch
        v = np.zeros((n, 6))
        v[moving] = deltas[moving] / d[moving, None]
        for j in range(n + 1):  # the velocity change at waypoint j, between segments j - 1 and j
            before = v[j - 1] if j > 0 else rest
            after = v[j] if j < n else rest
            around = [i for i in (j - 1, j) if 0 <= i < n and moving[i]]
            if not around:
                continue
            over = sum(d[i] for i in around) / 2.0
            need = _change_ok(before, after, over, accel, decel)
            if need > 1.0 + 1e-6:
                # Half the way (in ratio) per pass: a segment stretched for one end may already be enough for
                # the other, so stretching fully at once compounded (2 x planned slower than 1 x).
                step = math.sqrt(need) if need > 1.01 else need
                for i in around:
                    stretch[i] *= step
                    d[i] = durations[i] * stretch[i]
                    v[i] = deltas[i] / d[i]
                changed = True
        if not changed:
            break
    return np.concatenate(([0.0], np.cumsum(durations * stretch)))
