"""What the axes do after a move has ended on a force/torque limit (`AxisLaw.exceeded_action`).

- stop: the axis holds (zero velocity), as every axis does when a move ends. Today's behaviour, and the only
  reaction of an axis without a force limit.
- move_away: an axis whose |F| is at or above its limit when the move ends backs off along the axis, in the
  direction of the measured force (away from the contact), at `move_away_velocity_*` until |F| is below
  `move_away_release_fraction` times its limit, then holds: no standing press remains. It gives up (and
  holds) after `move_away_max_distance` / `_angle` of commanded travel, so a force that never drops (a bias,
  a contact that follows the arm) cannot drive the arm away indefinitely.
- gravity_compensation: the axis becomes a follower with its own damping (V = F / b, with the follower
  deadband): hand-guiding in that direction until `~stop`, a new request or a safety stop.

- (any law) coasting: a move that ended on its max travel, its normal end, slows its axes to rest over
  `end_stop_time` instead of stopping at once (`coast`): a tool sliding on a surface and stopped at once
  kicked the contact force up (README, *End conditions*).

The velocities go through the same shaping (minimum velocity, clamp, acceleration and deceleration limits,
immediate stop on reversal) as the laws', so a reaction never moves faster than a law could. Pure: no rospy.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

from contact_control.axes import (
    AXES,
    EXCEEDED_GRAVITY_COMPENSATION,
    EXCEEDED_MOVE_AWAY,
    LAW_FOLLOWER,
    LAW_NONE,
)
from contact_control.laws import AxisLaw, law_velocity, shape_velocity
from contact_control.params import AxisTuning

__all__ = ["ExceededReaction"]

_IDLE, _AWAY, _FOLLOW = 0, 1, 2


class ExceededReaction:
    """Per-axis exceeded actions of the move that just ended; `step` gives the velocities.

    Args:
        tuning: the six axes' tuning (velocity limits, move-away speed and distance).
        release_fraction: moving away ends when |F| < release_fraction * force limit.
    """

    def __init__(self, tuning: Sequence[AxisTuning], release_fraction: float) -> None:
        self.retune(tuning)
        self._release = release_fraction
        self._mode = [_IDLE] * 6
        self._laws: list[AxisLaw] = [AxisLaw()] * 6
        self._moved = [0.0] * 6
        self._coast = [0.0] * 6  # per axis: its deceleration to rest [m/s^2, rad/s^2] (0: none)

    def retune(self, tuning: Sequence[AxisTuning]) -> None:
        """New limits (live tuning); a running reaction goes on with them."""
        self._tuning = tuple(tuning)
        self._notes: list[str] = []
        self._moving = False  # some axis has a non-zero velocity (still decelerating after its reaction)

    @property
    def active(self) -> bool:
        """An axis is moving away, hand-guided, coasting to rest, or still slowing down after moving away."""
        return self._moving or any(self._mode) or any(self._coast)

    @property
    def moving_away(self) -> bool:
        """An axis is still backing off from its contact."""
        return _AWAY in self._mode

    def reacting(self) -> list[bool]:
        """Per axis: carrying out its exceeded action (backing off or hand-guided), or coasting to rest."""
        return [mode != _IDLE or coast > 0.0 for mode, coast in zip(self._mode, self._coast, strict=True)]

    def follower_axes(self) -> list[int]:
        """Axes under gravity compensation (they run the follower law)."""
        return [i for i in range(6) if self._mode[i] == _FOLLOW]

    @property
    def note(self) -> str:
        """What the reaction did or does, in words ('' when there is none)."""
        return "; ".join(self._notes)

    def clear(self) -> None:
        """No reaction (a new move, a stop, a safety trip)."""
        self._mode = [_IDLE] * 6
        self._notes = []
        self._moving = False
        self._coast = [0.0] * 6

    def coast(self, velocity: Sequence[float], duration: float) -> bool:
        """Slows the axes from `velocity` to rest over `duration` [s], each at a constant deceleration (not
        through the minimum velocity, which would stop one at once below it); returns whether any moves."""
        self.clear()
        if duration <= 0.0:
            return False
        self._coast = [abs(v) / duration for v in velocity]
        return self.active

    def start(self, laws: Sequence[AxisLaw], wrench: Sequence[float]) -> bool:
        """Starts the reactions of a move that ended on a force limit; returns whether any axis reacts.

        Args:
            laws: the ended move's six laws.
            wrench: the preprocessed wrench at the end [N, Nm], control frame.
        """
        self.clear()
        self._laws = list(laws)
        for i, law in enumerate(laws):
            if law.law == LAW_NONE or law.force_limit <= 0.0:
                continue
            unit = "Nm" if i >= 3 else "N"
            if law.exceeded_action == EXCEEDED_GRAVITY_COMPENSATION and law.damping > 0.0:
                self._mode[i] = _FOLLOW
                self._notes.append(f"{AXES[i]}: gravity compensation (follower, b = {law.damping:g})")
            elif law.exceeded_action == EXCEEDED_MOVE_AWAY and abs(wrench[i]) >= law.force_limit:
                self._mode[i] = _AWAY
                self._moved[i] = 0.0
                self._notes.append(
                    f"{AXES[i]}: moving away until |F| < {self._release * law.force_limit:.3g} {unit}"
                )
        return self.active

    def step(self, wrench: Sequence[float], velocity: list[float], dt: float) -> None:
        """One cycle: writes each axis's shaped velocity into `velocity` (in place).

        Args:
            wrench: preprocessed wrench [N, Nm], control frame.
            velocity: the velocities commanded last cycle; replaced by this cycle's.
            dt: time since the last cycle [s].
        """
        moving = False
        for i in range(6):
            mode, tuning, law = self._mode[i], self._tuning[i], self._laws[i]
            force = wrench[i]
            target = 0.0
            if mode == _FOLLOW:
                target = law_velocity(AxisLaw(LAW_FOLLOWER, damping=law.damping), tuning, force, 0.0)
            elif mode == _AWAY:
                unit, dist = ("Nm", "rad") if i >= 3 else ("N", "m")
                release = self._release * law.force_limit
                if abs(force) < release:
                    self._mode[i] = _IDLE
                    self._set_note(i, f"{AXES[i]}: moved away {self._moved[i]:.4g} {dist}, "
                                      f"|F| {abs(force):.3g} {unit} < {release:.3g}: holding")
                elif self._moved[i] >= tuning.away_max_travel:
                    self._mode[i] = _IDLE
                    self._set_note(i, f"{AXES[i]}: moved away the maximum {tuning.away_max_travel:g} {dist} "
                                      f"but |F| is still {abs(force):.3g} {unit}: holding")
                else:
                    target = math.copysign(tuning.away_velocity, force)  # along the force: off the contact
            rate = self._coast[i]
            if rate > 0.0:
                before, step = velocity[i], rate * dt
                v = 0.0 if abs(before) <= step else before - math.copysign(step, before)
                if v == 0.0:
                    self._coast[i] = 0.0
            else:
                v = shape_velocity(target, velocity[i], tuning, dt)
            velocity[i] = v
            self._moved[i] += abs(v) * dt
            moving = moving or v != 0.0
        self._moving = moving

    def _set_note(self, axis: int, text: str) -> None:
        prefix = f"{AXES[axis]}:"
        self._notes = [n for n in self._notes if not n.startswith(prefix)] + [text]
