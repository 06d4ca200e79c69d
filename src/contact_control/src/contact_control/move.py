"""The move's state: its id, how it ended (per axis, in words), the outcomes blocking callers wait for, and
the global-limit latch (no ROS here; the package README's "Moves")."""

from __future__ import annotations

from collections.abc import Sequence

from contact_control.axes import END_NONE

__all__ = ["MoveState"]

_OUTCOMES_KEPT = 64  # moves whose outcome a blocking caller may still ask for


class MoveState:
    """One move at a time: started, changed (a new id, nothing stops) or ended with a reason; the latch
    outranks them all until it is reset."""

    def __init__(self) -> None:
        self.active = False
        self.id = 0
        self.t0: float | None = None  # when the move started [s] (its wait for data counts from here)
        self.end: list[int] = [END_NONE] * 6  # per axis: the condition that ended the move
        self.ended_axis = -1  # the axis that ended it, -1: none or not a single axis
        self.ok = True  # ended by an axis end condition (force limit, max travel, force jump)
        self.message = "no move yet"
        self.latched = False
        self.latch_message = ""
        self._outcomes: dict[int, bool] = {}

    def begin(self, running: bool, t: float | None) -> int:
        """A new move; `running`: it has an active axis (else it is done at once, successfully)."""
        self.id += 1
        self.t0 = t
        self.end = [END_NONE] * 6
        self.ended_axis = -1
        self.active = running
        self.ok = True
        self.message = "" if running else "no laws set"
        if not running:
            self._outcomes[self.id] = True
        return self.id

    def change(self) -> int:
        """The running move goes on under new laws with a new id (the old one's caller is answered)."""
        self.end = [END_NONE] * 6
        self.ended_axis = -1
        self.id += 1
        self.active = True
        self.ok = True
        self.message = ""
        return self.id

    def finish(self, axis: int, condition: int, ok: bool, message: str, active: Sequence[int]) -> None:
        """The move ends by `condition` on `axis` (-1: on every `active` axis)."""
        self.end = [END_NONE] * 6
        for i in (axis,) if axis >= 0 else active:
            self.end[i] = condition
        self.ended_axis = axis
        self.active = False
        self.ok = ok
        self.message = f"move ended: {message}"
        self._outcomes[self.id] = ok
        self._outcomes.pop(self.id - _OUTCOMES_KEPT, None)

    def outcome(self, move_id: int, still_running: bool) -> bool | None:
        """None while move `move_id` runs (`still_running` also counts a press being released), then whether
        it ended by an axis end condition."""
        if move_id == self.id and still_running:
            return None
        return self._outcomes.get(move_id, False)

    def without_data(self, t: float, last: float | None) -> float:
        """How long [s] the running move has been without a wrench at `t` (`last`: the newest one's time)."""
        if not self.t0 and t > 0.0:
            # Set under sim time before the clock ran (a law set before `rosbag play --clock`): the move's
            # wait for data starts with the clock, or it would end the moment the bag's clock appears.
            self.t0 = t
        since = last if last is not None else self.t0
        if self.t0 is not None and (since is None or since < self.t0):
            since = self.t0
        return 0.0 if since is None else t - since

    def latch(self, message: str) -> None:
        self.latched = True
        self.latch_message = message

    def unlatch(self) -> bool:
        """Clears the latch; returns whether it was set."""
        was, self.latched, self.latch_message = self.latched, False, ""
        return was
