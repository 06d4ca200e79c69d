"""Clamp release (ISO/TS 15066; the package README, *Clamping*): a contact force at or over the body region's
quasi-static limit for `hold` seconds is a clamp (a person pinned between the tool and something), and so
is one at or over `push_limit` for `hold` while the contact guard holds a push into it back: the arm pins
what it touched, whether it overshot the guard or the guard's slow zone landed it at its limit. The arm
then backs off along the measured force at `speed` until the force is below `release`, whatever it was
commanded, and stops. A shorter peak (a strike, a spike) is not a clamp. No ROS here.

Without a fresh, finite force the direction away is unknown: nothing is released, and the command stands
(the contact guard stops outside twists on such a force).
"""

from __future__ import annotations

import math
from collections.abc import Sequence

__all__ = ["ClampRelease"]


class ClampRelease:
    """Watches the contact force each cycle; `check` gives the retreat while a clamp is released.

    Args:
        limit: |F| [N] at or over which a sustained contact is a clamp (the region's quasi-static force).
        push_limit: the same while a push into the contact is being held back (slowed or stopped).
        hold: how long [s] |F| must stay at or over `limit`.
        speed: retreat speed [m/s] along the force.
        release: the retreat ends below this |F| [N].
        travel: the retreat ends after this far [m] whatever the force (a stuck sensor, something that
            follows the tool): `stuck` says so, and no new clamp is found until |F| is below `release`.
    """

    def __init__(self, limit: float, push_limit: float, hold: float, speed: float, release: float,
                 travel: float = math.inf) -> None:
        self.limit, self.push_limit = limit, push_limit
        self.hold, self.speed, self.release, self.travel = hold, speed, release, travel
        self._over_since: float | None = None
        self._since = 0.0  # when the clamp being released was found
        self.active = False
        self.stuck = False  # the last retreat ran its `travel` with the force still at or over `release`
        self.peak = 0.0  # the largest |F| of the clamp being released [N]
        self.by_push = False  # it was found over `push_limit` (not over `limit`)

    def limit_words(self, region: str) -> str:
        """Which limit the clamp being released crossed, in words."""
        if self.by_push:
            return f"{self.push_limit:g} N while a push into it was held back"
        return f"the {region}'s {self.limit:g} N (ISO/TS 15066)"

    def check(self, force: Sequence[float] | None, age: float, timeout: float, t: float, pushed: bool = False
              ) -> tuple[float, float, float] | None:
        """The retreat velocity (along the force, in its frame) [m/s] while a clamp is released, else None.

        Args:
            force: the contact force on the tool (fx, fy, fz) [N]; None: none received.
            age: how old it is [s]; older than `timeout` counts as none.
            t: now [s].
            pushed: a push into the contact is being held back now.
        """
        if force is None or age > timeout:
            self._over_since = None
            return None
        fx, fy, fz = (float(f) for f in force)
        magnitude = math.sqrt(fx * fx + fy * fy + fz * fz)
        if not math.isfinite(magnitude):
            self._over_since = None
            return None
        if self.stuck:
            self.stuck = magnitude >= self.release
            return None
        if self.active:
            if magnitude < self.release:
                self.active, self._over_since = False, None
                return None
            if (t - self._since) * self.speed >= self.travel:
                self.active, self.stuck, self._over_since = False, True, None
                return None
        elif magnitude >= (min(self.limit, self.push_limit) if pushed else self.limit):
            if self._over_since is None:
                self._over_since = t
            if t - self._over_since < self.hold:
                return None
            self.active, self.peak, self.by_push, self._since = True, 0.0, magnitude < self.limit, t
        else:
            self._over_since = None
            return None
        self.peak = max(self.peak, magnitude)
        k = self.speed / magnitude
        return (fx * k, fy * k, fz * k)
