"""Contact-force guard for jogging from an outside source (keyboard, `rostopic pub`, a GUI).

Pure: no rospy. It takes the compensated contact force on the tool (the force the contact exerts on it, as
contact_control measures it: a table under the tool pushes +Z) expressed in the frame of the twist, and the
twist, and returns the twist it lets through:

- |F| below `slow_force`: the twist passes unchanged.
- `slow_force` <= |F| < `max_force`: the twist's linear component *into* the contact (against F) is capped
  at `slow_speed`, falling linearly to zero at `max_force`, so a tool that touches something slows down
  before the force is at the limit (the force is measured tens of milliseconds late on a stiff arm).
- |F| >= `max_force`: a twist with a component into the contact is stopped whole (its sideways part too:
  sliding under friction at the limit strains the contact further) and rotation is removed (a rotation can
  lever the tool into the surface); moving away from the contact and along it still pass. A push into the
  contact becomes a slow retreat along the force (at most `relief_speed`, never faster than the push) until
  |F| is below RELIEF_RELEASE (0.9) of `max_force`: a stiff arm that overshot into the contact does not keep
  pressing at the limit while the key is held. From then on motion into the contact stays blocked until |F|
  falls below `slow_force` (hysteresis: no creeping back to the limit).
- The force is stale (older than `timeout`): the whole twist is stopped. No force yet at all: the twist
  passes and the result says the guard is not active (a stack without a sensor keeps jogging).

The guard only ever makes a twist slower, never faster. `GuardResult.message` says why it acted.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

__all__ = ["ContactGuard", "GuardResult"]

_EPS = 1e-9
RELIEF_RELEASE = 0.9  # a retreat from over max_force goes on until |F| < this fraction of it (hysteresis)


@dataclass(frozen=True)
class GuardResult:
    """What the guard let through.

    Attributes:
        twist: (vx, vy, vz [m/s], wx, wy, wz [rad/s]) after the guard, in the input's frame.
        acted: the twist was changed (slowed, cut or stopped).
        blocked: motion into the contact was stopped entirely (at the limit, or stale force).
        message: why, in words ('' when the twist passed and the guard is active).
        force: |F| [N] the decision used (NaN without a force).
    """

    twist: tuple[float, ...]
    acted: bool
    blocked: bool
    message: str
    force: float


class ContactGuard:
    """Limits outside twists by the measured contact force; see the module docstring.

    Args:
        max_force: |F| [N] at or above which motion into the contact stops.
        slow_force: |F| [N] from which motion into the contact is slowed (< max_force).
        slow_speed: into-contact speed cap [m/s] at slow_force, falling to zero at max_force.
        timeout: a force older than this [s] stops the twist.
        relief_speed: retreat speed [m/s] that replaces a push into a contact at or above max_force.

    Raises:
        ValueError: a value out of range (named).
    """

    def __init__(
        self,
        max_force: float,
        slow_force: float,
        slow_speed: float,
        timeout: float,
        relief_speed: float = 0.005,
    ) -> None:
        self.retune(max_force, slow_force, slow_speed, timeout, relief_speed)
        self._blocked = False  # reached max_force: into-contact motion stays blocked until below slow_force
        self._relieving = False  # reached max_force: a push into the contact backs off until RELIEF_RELEASE

    def retune(self, max_force: float, slow_force: float, slow_speed: float, timeout: float,
               relief_speed: float) -> None:
        """New thresholds, checked as at start-up (nothing changes on a ValueError); a block stays."""
        for name, value in (("max_force", max_force), ("slow_speed", slow_speed), ("timeout", timeout),
                            ("relief_speed", relief_speed)):
            if not (value > 0.0 and math.isfinite(value)):
                raise ValueError(f"contact guard: {name} must be finite and > 0, got {value}")
        if not 0.0 <= slow_force < max_force:
            raise ValueError(f"contact guard: slow_force must be in [0, max_force {max_force}), "
                             f"got {slow_force}")
        self.max_force = max_force
        self.slow_force = slow_force
        self.slow_speed = slow_speed
        self.timeout = timeout
        self.relief_speed = relief_speed

    def limit(self, twist: Sequence[float], force: Sequence[float] | None, age: float = 0.0) -> GuardResult:
        """The twist the guard lets through.

        Args:
            twist: (vx, vy, vz, wx, wy, wz) [m/s, rad/s] in some frame.
            force: the contact force (fx, fy, fz) [N] on the tool in the same frame; None: none received yet.
            age: how old the force is [s].
        """
        v = tuple(float(x) for x in twist)
        if force is None:
            return GuardResult(v, False, False, "no contact force received yet: not guarded", math.nan)
        fx, fy, fz = (float(x) for x in force)
        magnitude = math.sqrt(fx * fx + fy * fy + fz * fz)
        if not (age <= self.timeout and math.isfinite(magnitude)):
            why = f"contact force is {age:.3f} s old (timeout {self.timeout} s)" if math.isfinite(magnitude) \
                else "contact force is not finite"
            moving = any(v)
            return GuardResult((0.0,) * 6, moving, moving, f"contact guard: {why}: outside motion stopped",
                               magnitude)
        if magnitude < self.slow_force or magnitude < _EPS:
            self._blocked = self._relieving = False
            return GuardResult(v, False, False, "", magnitude)
        over = magnitude >= self.max_force
        self._blocked = self._blocked or over
        self._relieving = over or (self._relieving and magnitude >= RELIEF_RELEASE * self.max_force)
        over = self._relieving
        ux, uy, uz = fx / magnitude, fy / magnitude, fz / magnitude
        into = -(v[0] * ux + v[1] * uy + v[2] * uz)  # > 0: into the contact (against the force)
        if self._blocked:
            cap = 0.0
        else:
            cap = self.slow_speed * (self.max_force - magnitude) / (self.max_force - self.slow_force)
        rotating = self._blocked and any(v[3:])
        if into <= cap + _EPS and not rotating:
            return GuardResult(v, False, False, "", magnitude)
        blocked = self._blocked
        if blocked and into > _EPS:
            # A push into a contact at the limit stops entirely, its sideways part too (sliding under friction
            # at the limit strains the contact further); over the limit it becomes a slow retreat along F.
            back = min(self.relief_speed, into) if over else 0.0
            linear = (back * ux, back * uy, back * uz)
        else:
            cut = max(into - cap, 0.0)  # remove this much of the into-contact component
            linear = (v[0] + cut * ux, v[1] + cut * uy, v[2] + cut * uz)
        angular = (0.0, 0.0, 0.0) if blocked else v[3:]
        if over:
            what = "motion into the contact stopped, backing off (moving away is allowed)"
        elif blocked:
            what = f"motion into the contact stopped until below {self.slow_force:g} N (moving away is " \
                "allowed)"
        else:
            what = f"motion into the contact slowed to {cap * 1e3:.1f} mm/s (moving away is allowed)"
        message = f"contact guard: {magnitude:.1f} N contact force (limit {self.max_force:g} N): {what}"
        return GuardResult((*linear, *angular), True, blocked, message, magnitude)
