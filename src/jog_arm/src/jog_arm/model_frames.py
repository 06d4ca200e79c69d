"""Poses of robot-model frames at the measured joint state (no tf needed in the same process).

A controller that runs beside the jogger (contact_control in control_stack, jog_arm's contact guard) asks
for a few frames per wrench; each answer is computed once per joint state (kept while the joints do not move).
"""

from __future__ import annotations

from collections.abc import Callable

from jog_arm.kinematics import ArmModel

__all__ = ["ModelFrames", "Rows"]

Rows = list[list[float]]  # a 4x4 homogeneous transform as rows


class ModelFrames:
    """`pose(frame, relative_to)` at the joint state `measured()` returns (model order, None before one).

    Args:
        model: The arm model.
        measured: Returns the current measured positions; a new list object per joint state.
    """

    def __init__(self, model: ArmModel, measured: Callable[[], list[float] | None]) -> None:
        self._model = model
        self._measured = measured
        self._ids: dict[tuple[str, str], tuple[int, int] | None] = {}
        self._poses: dict[tuple[str, str], Rows] = {}
        self._q: object = None

    def has(self, frame: str, relative_to: str) -> bool:
        """Whether both are frames of the model."""
        return self._frame_ids(frame, relative_to) is not None

    def _frame_ids(self, frame: str, relative_to: str) -> tuple[int, int] | None:
        key = (frame, relative_to)
        if key not in self._ids:
            model = self._model
            known = model.has_frame(frame) and model.has_frame(relative_to)
            self._ids[key] = (model.frame_id(frame), model.frame_id(relative_to)) if known else None
        return self._ids[key]

    def pose(self, frame: str, relative_to: str) -> Rows | None:
        """Pose (4x4 rows) of `frame` in `relative_to`; None if either is not a model frame. The rows are
        shared until a joint state with other positions: do not modify them.

        Raises:
            LookupError: No joint state received yet.
        """
        ids = self._frame_ids(frame, relative_to)
        if ids is None:
            return None
        q = self._measured()
        if q is None:
            raise LookupError("no joint state received yet")
        if q is not self._q:  # a new joint state: earlier answers are out of date unless it did not move
            if q != self._q:
                self._poses.clear()
            self._q = q
        key = (frame, relative_to)
        pose = self._poses.get(key)
        if pose is None:
            pose = self._poses[key] = self._model.measured_pose(q, *ids).tolist()
        return pose
