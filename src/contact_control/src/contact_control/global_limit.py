"""The global wrench limits' trip (the package README, *Safety*): a wrench over `global_max_force` or
`global_max_torque` for `force_limit_samples` wrenches in a row latches the safety until a reset; fewer are
a spike, and the last command stands meanwhile. No ROS here.
"""

from __future__ import annotations

from collections.abc import Sequence

__all__ = ["GlobalLimit"]


class GlobalLimit:
    """Counts wrenches in a row over a global limit.

    Args:
        samples: wrenches in a row over a limit that trip it.
    """

    def __init__(self, samples: int) -> None:
        self.samples = samples
        self._over = 0

    def spike(self, over: bool, latched: bool) -> bool:
        """Whether this wrench is ridden out: over a limit, but not yet `samples` in a row and not latched (a
        15 N push on a 3.6 N current estimate crossed 25 N on single samples)."""
        self._over = self._over + 1 if over else 0
        return over and self._over < self.samples and not latched

    @staticmethod
    def message(w: Sequence[float] | None, max_force: float, max_torque: float) -> str:
        """The latch's reason: the wrench that tripped against the limits."""
        force = (w[0] ** 2 + w[1] ** 2 + w[2] ** 2) ** 0.5 if w else float("nan")
        torque = (w[3] ** 2 + w[4] ** 2 + w[5] ** 2) ** 0.5 if w else float("nan")
        return (f"wrench over the global limit (|F| {force:.1f} N of {max_force} N, |T| {torque:.1f} Nm of "
                f"{max_torque} Nm): holding until reset")
