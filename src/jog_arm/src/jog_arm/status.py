"""Status codes of the jog_arm server; the values are those of compliant_control_msgs/JogStatus."""

from __future__ import annotations

from enum import IntEnum

__all__ = ["StatusCode"]


class StatusCode(IntEnum):
    """Why the output is what it is this cycle (worst reason wins)."""

    NO_WARNING = 0
    DECELERATE_FOR_SINGULARITY = 1
    HALT_FOR_SINGULARITY = 2
    DECELERATE_FOR_JOINT_LIMIT = 3
    HALT_FOR_JOINT_LIMIT = 4
    JOINT_VELOCITY_SCALED = 5
    STALE_COMMAND = 6
    INVALID_COMMAND = 7
    PAUSED = 8
    NO_JOINT_STATE = 9
    STALE_JOINT_STATE = 10
    CONTACT_GUARD = 11
