"""The per-axis contact laws (GCCF, with the thesis fork's refinements as named parameters).

F is the force [N] (torque [Nm] on rotational axes) along the axis in the control frame, d the travel since
the law was set [m] ([rad]), V the commanded velocity [m/s] ([rad/s]):

- follower: V = F / b when |F| > deadband, else 0 (the rate limit then decelerates smoothly); |V| at most
  `velocity` when that is > 0 (hand-guiding's speed cap).
- spring: V = scale * round(round(F) / b - k (d + d_offset)), rounding to `spring_rounding`.
  k is in 1/s here (GCCF's form), the equivalent impedance stiffness is b * k [N/m].
- compliant move: V = V_desired + F / b (no force term when b = 0); within `slowdown` of the max travel the
  speed falls linearly with the remaining travel, never below `approach_speed`.
- force tracking: V = (F - F_target) / b, so the axis presses until the contact force F reaches the target
  (F as the follower reads it: a table under the tool pushes +Z, so pressing down with 10 N is F_target 10).
  No deadband around zero force (free air must move the tool toward the contact), but V = 0 while
  |F - F_target| <= `track_deadband` and outside it V = (F - F_target -+ track_deadband) / b, continuous at
  the band's edge; no minimum velocity (a stiff surface needs a large b, so small
  corrections are slow ones). Out of contact (F short of `contact_fraction` of the target, on the target's
  side) the axis approaches at the law's approach speed (`velocity`) toward the contact: (F - F_target) / b
  with a b fit for a stiff surface would creep through free air, with a small b it would hit the surface.
- path: V = v_ref + k e (+ F / b when b > 0, outside the follower's deadband), e the pose error to a reference
  that moves (a replay streams it, `path_ref.PathReference`): a spring whose anchor travels along the path,
  with the path's velocity fed forward. `max_travel` bounds |e| (PATH_ERROR).
- normal (RX/RY): W = k theta, theta the turn that brings the tool's axis onto the contact normal estimated
  from the force (`normal.NormalFollower`, `normal.normal_velocity`); at most `velocity` when > 0.
- none: V = 0.

`shape_velocity` then zeroes |V| <= min_velocity, clamps to the max velocity and limits acceleration and
deceleration; a reversal of direction stops at once and then accelerates the other way.
`check_end` gives GCCF's per-axis end conditions; `ForceWindow` the force-jump one.
"""

from __future__ import annotations

import math
from collections import deque
from dataclasses import dataclass

from contact_control.axes import (
    END_FT_VIOLATION,
    END_MAX_TRAVEL,
    END_NONE,
    EXCEEDED_STOP,
    LAW_COMPLIANT_MOVE,
    LAW_FOLLOWER,
    LAW_FORCE_TRACKING,
    LAW_NONE,
    LAW_SPRING,
)
from contact_control.params import AxisTuning

__all__ = [
    "AxisLaw", "ForceWindow", "check_end", "guard_pressing", "law_velocity", "path_velocity", "round_to",
    "shape_velocity", "short_of_contact",
]


@dataclass(frozen=True)
class AxisLaw:
    """The law of one axis and its parameters (units per axis kind: N or Nm, m or rad, s).

    Attributes:
        law: LAW_NONE, LAW_FOLLOWER, LAW_SPRING, LAW_COMPLIANT_MOVE or LAW_FORCE_TRACKING.
        damping: b [N/(m/s)] or [Nm/(rad/s)]; > 0 for follower, spring and force tracking, >= 0 for compliant
            move.
        stiffness: k [1/s] of the spring law.
        velocity: V_desired of the compliant move [m/s] or [rad/s]; its sign is the direction. Force tracking:
            the approach speed (> 0) while out of contact. Follower: a speed cap (> 0; 0: none).
        force_limit: |F| at or above this ends the move (FT_VIOLATION); 0: no limit.
        max_travel: |d| at or above this ends the move (MAX_TRAVEL); 0: no limit.
        offset: d_offset of the spring law [m] or [rad].
        exceeded_action: EXCEEDED_STOP, EXCEEDED_MOVE_AWAY or EXCEEDED_GRAVITY_COMPENSATION: what this axis
            does once the move has ended on a force limit (see `exceeded.ExceededReaction`).
        target: F_target of force tracking [N] or [Nm], in the sign convention of F.
    """

    law: int = LAW_NONE
    damping: float = 0.0
    stiffness: float = 0.0
    velocity: float = 0.0
    force_limit: float = 0.0
    max_travel: float = 0.0
    offset: float = 0.0
    exceeded_action: int = EXCEEDED_STOP
    target: float = 0.0


def round_to(value: float, step: float) -> float:
    """`value` rounded to a multiple of `step` (unchanged when step is 0)."""
    return round(value / step) * step if step else value


def law_velocity(law: AxisLaw, tuning: AxisTuning, force: float, travel: float) -> float:
    """The law's velocity before shaping."""
    kind = law.law
    if kind == LAW_FOLLOWER:
        if -tuning.deadband <= force <= tuning.deadband:
            return 0.0
        v = force / law.damping
        cap = law.velocity  # hand-guiding's speed cap (0: none but the clamp)
        if cap > 0.0 and not -cap <= v <= cap:
            return cap if v > 0.0 else -cap
        return v
    if kind == LAW_SPRING:
        step = tuning.spring_rounding
        v = round_to(force, step) / law.damping - law.stiffness * (travel + law.offset)
        return tuning.spring_scale * round_to(v, step)
    if kind == LAW_COMPLIANT_MOVE:
        speed = abs(law.velocity)
        if law.max_travel > 0.0 and tuning.slowdown > 0.0:
            remaining = law.max_travel - abs(travel)
            if remaining < tuning.slowdown:
                speed = max(min(speed, tuning.approach_speed), speed * remaining / tuning.slowdown)
        v = math.copysign(speed, law.velocity)
        if law.damping > 0.0:
            v += force / law.damping
        return v
    if kind == LAW_FORCE_TRACKING:
        error = force - law.target
        band = tuning.track_deadband
        if -band <= error <= band:
            return 0.0
        # Continuous at the band's edge: stepping to band / b there made a relay whose steps, held for the
        # filter's delay against a stiff surface, swung the force by +-2 N (README, *Force tracking*).
        v = (error - math.copysign(band, error)) / law.damping
        # Out of contact: toward it at the approach speed, which sets the overshoot on touching; never
        # faster for a small b.
        if short_of_contact(law.target, tuning.contact_fraction, force):
            return -law.velocity if law.target > 0.0 else law.velocity
        return v
    return 0.0


def short_of_contact(target: float, fraction: float, force: float) -> bool:
    """Force tracking is out of contact: `force` short of `fraction` of a nonzero `target` on its side."""
    return force < fraction * target if target > 0.0 else target < 0.0 and force > fraction * target


def guard_pressing(law: AxisLaw, tuning: AxisTuning, v: float, fast: float) -> float:
    """Force tracking's velocity `v` with its pressing (toward the contact) capped by the unfiltered force
    `fast`: once that is in contact (past `contact_fraction` of the target), at most (F_target - fast) / b
    (deadband as in the law), 0 past the target. It never pulls back (that stays with the filtered force, so
    noise cannot make it retreat): a touch stops the pressing a filter delay sooner (README, *Force
    tracking*)."""
    target = law.target
    if target > 0.0:
        if v >= 0.0 or fast < tuning.contact_fraction * target:
            return v
        cap = (fast - target + tuning.track_deadband) / law.damping  # < 0 while short of the target's band
        return max(v, min(cap, 0.0))
    if target < 0.0:
        if v <= 0.0 or fast > tuning.contact_fraction * target:
            return v
        cap = (fast - target - tuning.track_deadband) / law.damping
        return min(v, max(cap, 0.0))
    return v


def path_velocity(law: AxisLaw, tuning: AxisTuning, force: float, error: float, reference: float) -> float:
    """The path law's velocity before shaping: V = v_ref + k e, plus F / b outside the follower's deadband
    when b > 0 (a push moves the tool off the path, the spring to the moving reference brings it back)."""
    v = reference + law.stiffness * error
    if law.damping > 0.0 and not -tuning.deadband <= force <= tuning.deadband:
        v += force / law.damping
    return v


def shape_velocity(
    target: float, previous: float, tuning: AxisTuning, dt: float, floor: bool = True
) -> float:
    """Applies min velocity, the velocity clamp and the acceleration/deceleration limits.

    Args:
        target: the law's velocity.
        previous: the velocity commanded last cycle.
        tuning: limits of this axis kind.
        dt: time since the last cycle [s].
        floor: zero |target| <= min velocity (False for force tracking, which has its own deadband).
    """
    if floor and -tuning.min_velocity <= target <= tuning.min_velocity:
        target = 0.0
    elif target > tuning.max_velocity:
        target = tuning.max_velocity
    elif target < -tuning.max_velocity:
        target = -tuning.max_velocity
    if target * previous < 0.0:
        # Reversal (pushed the other way): stop at once rather than keep moving against the push.
        previous = 0.0
    if (previous >= 0.0 and target > previous) or (previous <= 0.0 and target < previous):
        step = tuning.acceleration * dt  # speeding up (from rest or in the same direction)
    else:
        step = tuning.deceleration * dt
    if target > previous + step:
        return previous + step
    if target < previous - step:
        return previous - step
    return target


def check_end(law: AxisLaw, force: float, travel: float) -> int:
    """END_FT_VIOLATION, END_MAX_TRAVEL or END_NONE for this axis (force first, as GCCF)."""
    if law.force_limit > 0.0 and abs(force) >= law.force_limit:
        return END_FT_VIOLATION
    if law.max_travel > 0.0 and abs(travel) >= law.max_travel:
        return END_MAX_TRAVEL
    return END_NONE


class ForceWindow:
    """Spread (max - min) of a force over the last `window` seconds, amortised O(1) per sample."""

    def __init__(self, window: float) -> None:
        self.window = window
        self._max: deque[tuple[float, float]] = deque()
        self._min: deque[tuple[float, float]] = deque()

    def clear(self) -> None:
        self._max.clear()
        self._min.clear()

    def add(self, t: float, force: float) -> float:
        """Adds a sample at time `t` [s] and returns the spread over (t - window, t]."""
        hi, lo = self._max, self._min
        while hi and hi[-1][1] <= force:
            hi.pop()
        hi.append((t, force))
        while lo and lo[-1][1] >= force:
            lo.pop()
        lo.append((t, force))
        oldest = t - self.window
        while hi[0][0] < oldest:
            hi.popleft()
        while lo[0][0] < oldest:
            lo.popleft()
        return hi[0][1] - lo[0][1]
