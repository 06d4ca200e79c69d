"""One control cycle's outcome: the twist, the wrench, the travel, each axis's law and end, the safety state
and why (what contact_control's ~status and events publish; no ROS here)."""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from compliant_common.typedefs import FloatArray

from contact_control.axes import AXES

__all__ = ["AxisState", "CycleResult"]


class AxisState(NamedTuple):
    """One axis of a cycle, as in compliant_control_msgs/AxisState."""

    axis: str
    law: int
    end_condition: int
    force: float
    velocity: float
    travel: float


class CycleResult:
    """The outcome of one cycle. Lists are fresh each cycle, so a result may be kept.

    Attributes:
        t: cycle time [s].
        velocity: commanded twist (vx, vy, vz [m/s], wx, wy, wz [rad/s]) in the control frame.
        wrench: preprocessed wrench in the control frame [N, Nm] (the last valid one while holding).
        travel: travel since the law was set [m, rad].
        laws: law type per axis.
        end_conditions: end condition per axis (non-zero on the axis that ended the move).
        move_active: laws set and no end condition met.
        safety: SAFETY_* code; message: why, in words ('' when all is well).
        ended_axis: index of the axis that ended the move, -1 if none or not a single axis.
        move_id: counts `set_laws` calls.
        reacting: per axis, carrying out its exceeded action after the move ended (moving away, following).
        actions: per axis, the exceeded action (EXCEEDED_*) of its law; -1 on axes without a force limit.
    """

    __slots__ = (
        "actions",
        "end_conditions",
        "ended_axis",
        "laws",
        "message",
        "move_active",
        "move_id",
        "reacting",
        "safety",
        "t",
        "travel",
        "velocity",
        "wrench",
    )

    def __init__(
        self,
        t: float,
        velocity: list[float],
        wrench: list[float],
        travel: list[float],
        laws: list[int],
        end_conditions: list[int],
        move_active: bool,
        safety: int,
        message: str,
        ended_axis: int,
        move_id: int,
        reacting: list[bool] | None = None,
        actions: list[int] | None = None,
    ) -> None:
        self.t = t
        self.velocity = velocity
        self.wrench = wrench
        self.travel = travel
        self.laws = laws
        self.end_conditions = end_conditions
        self.move_active = move_active
        self.safety = safety
        self.message = message
        self.ended_axis = ended_axis
        self.move_id = move_id
        self.reacting = reacting if reacting is not None else [False] * 6
        self.actions = actions if actions is not None else [-1] * 6

    @property
    def commanding(self) -> bool:
        """Twists are due: a move runs, or an axis carries out its exceeded action after it."""
        return self.move_active or any(self.reacting)

    @property
    def twist(self) -> FloatArray:
        """The commanded twist as a numpy array (6,), control frame."""
        return np.array(self.velocity)

    @property
    def axes(self) -> list[AxisState]:
        return [
            AxisState(
                AXES[i],
                self.laws[i],
                self.end_conditions[i],
                self.wrench[i],
                self.velocity[i],
                self.travel[i],
            )
            for i in range(6)
        ]

    def __repr__(self) -> str:
        return (
            f"CycleResult(t={self.t}, velocity={self.velocity}, safety={self.safety}, "
            f"move_active={self.move_active}, message={self.message!r})"
        )
