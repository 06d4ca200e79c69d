"""Contact events from the cycle results: touch, release, force limit exceeded, move ended.

One `EventWatch.observe` per cycle compares the result with the previous one (a few comparisons, no
allocation unless an event fires). Touch and release use the contact force |F| (the preprocessed force of the
control frame: tool weight, bias and noise filtered out) with hysteresis: touch at `touch_force`, release
below `release_force`. Holds (stale, NaN, missing frame) are skipped: their wrench is an old one.
"""

from __future__ import annotations

import math
from typing import NamedTuple

from contact_control.axes import END_FT_VIOLATION, SAFETY_OK, SAFETY_OVER_LIMIT
from contact_control.cycle import CycleResult

__all__ = ["EVENT_NAMES", "FORCE_LIMIT", "MOVE_ENDED", "RELEASE", "TOUCH", "ContactEvent", "EventWatch"]

# compliant_control_msgs/ContactEvent types
TOUCH = 1
RELEASE = 2
FORCE_LIMIT = 3
MOVE_ENDED = 4
EVENT_NAMES = {TOUCH: "touch", RELEASE: "release", FORCE_LIMIT: "force_limit", MOVE_ENDED: "move_ended"}


class ContactEvent(NamedTuple):
    """One event: its type, the cycle time [s], the wrench (control frame) [N, Nm], the move it belongs to
    (0: none yet), what happened in words and where the end effector was."""

    kind: int
    t: float
    wrench: tuple[float, ...]
    move_id: int
    message: str
    pose: list[list[float]] | None = None  # the EEF in the fixed frame (4x4 rows), filled by the stage


class EventWatch:
    """Turns consecutive cycle results into `ContactEvent`s, appended to `pending` (drained by the caller).

    Args:
        touch_force: |F| [N] at which a touch is reported.
        release_force: |F| [N] below which a release is reported (< touch_force).
    """

    def __init__(self, touch_force: float, release_force: float) -> None:
        if not 0.0 <= release_force < touch_force:
            raise ValueError(f"release_force {release_force} must be in [0, touch_force {touch_force})")
        self._touch = touch_force
        self._release = release_force
        self.touching = False
        self._move_id = 0
        self._active = False
        self._over = False
        self.pending: list[ContactEvent] = []

    def observe(self, r: CycleResult, end_message: str) -> None:
        """One cycle's result; `end_message` says how the last move ended (ContactControl.end_message)."""
        if r.safety == SAFETY_OK:  # holds carry an old wrench
            w = r.wrench
            force = math.sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2])
            if not self.touching and force >= self._touch:
                self.touching = True
                self._add(TOUCH, r, f"touch: {force:.1f} N contact force (touch_force {self._touch:g} N)")
            elif self.touching and force < self._release:
                self.touching = False
                self._add(RELEASE, r, f"release: {force:.1f} N contact force (release_force "
                                      f"{self._release:g} N)")
        if r.safety == SAFETY_OVER_LIMIT:
            if not self._over:
                self._over = True
                if not self.touching:  # a jump past the global limit passed the touch force unfiltered
                    self.touching = True
                    self._add(TOUCH, r, "touch: the contact force jumped over the global limit")
                self._add(FORCE_LIMIT, r, r.message or "over the global force/torque limit")
        else:
            self._over = False
        if self._active and (not r.move_active or r.move_id != self._move_id):
            old = self._move_id
            if r.move_id != old:
                self._add(MOVE_ENDED, r, f"move {old} replaced by move {r.move_id}", old)
            else:
                if r.ended_axis >= 0 and r.end_conditions[r.ended_axis] == END_FT_VIOLATION:
                    self._add(FORCE_LIMIT, r, end_message, old)
                self._add(MOVE_ENDED, r, end_message, old)
        self._active, self._move_id = r.move_active, r.move_id

    def _add(self, kind: int, r: CycleResult, message: str, move_id: int | None = None) -> None:
        self.pending.append(
            ContactEvent(kind, r.t, tuple(r.wrench), r.move_id if move_id is None else move_id, message)
        )
