"""Status codes of the jog_arm server (the values are those of compliant_control_msgs/JogStatus), and the
status of a cycle that follows a command."""

from __future__ import annotations

from enum import IntEnum

__all__ = ["StatusCode", "motion_status"]


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
    COLLABORATIVE_SPEED_CAP = 12
    CLAMP_RELEASE = 13
    ROBOT_STOPPED = 14


def motion_status(condition: float, s_sing: float, s_pos: float, s_vel: float,
                  s_cap: float = 1.0) -> tuple[StatusCode, str]:
    """Status of a cycle that follows a command, from the scales applied to it (a halt before a slow-down,
    the singularity before the joint limits, the collaborative speed cap before the joint velocities; the
    caller words the cap's message)."""
    if s_sing == 0.0:
        return StatusCode.HALT_FOR_SINGULARITY, f"halted: condition number {condition:.1f} at hard stop"
    if s_pos == 0.0:
        return StatusCode.HALT_FOR_JOINT_LIMIT, "halted: a joint is at its position limit margin"
    if s_sing < 1.0:
        return (
            StatusCode.DECELERATE_FOR_SINGULARITY,
            f"slowing down near a singularity: condition number {condition:.1f}",
        )
    if s_pos < 1.0:
        return StatusCode.DECELERATE_FOR_JOINT_LIMIT, "slowing down near a joint position limit"
    if s_cap < 1.0:
        return StatusCode.COLLABORATIVE_SPEED_CAP, "speed capped (ISO/TS 15066)"
    if s_vel < 1.0:
        return StatusCode.JOINT_VELOCITY_SCALED, "command scaled to the joint velocity limits"
    return StatusCode.NO_WARNING, "moving"
