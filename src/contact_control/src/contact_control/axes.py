"""Axis names and the integer codes shared with the messages.

The values equal the constants of `cartesian_impedance_msgs/ControlLaw`, `compliant_control_msgs/AxisState`
and `compliant_control_msgs/ContactControlStatus`, so the node copies them into messages unchanged. Each
set is an IntEnum with a name map; a member compares and hashes as its int, as fast (the control loop
compares them every cycle).
"""

from __future__ import annotations

from enum import IntEnum

__all__ = [
    "ANGULAR_AXES",
    "AXES",
    "END_DIFF_VIOLATION",
    "END_EXTERNAL_STOP",
    "END_FT_VIOLATION",
    "END_MAX_TRAVEL",
    "END_NAMES",
    "END_NONE",
    "END_NO_FT_DATA",
    "END_OSCILLATION",
    "END_PATH_ERROR",
    "END_PATH_LOST",
    "EXCEEDED_ACTION_NAMES",
    "EXCEEDED_GRAVITY_COMPENSATION",
    "EXCEEDED_MOVE_AWAY",
    "EXCEEDED_STOP",
    "LAW_COMPLIANT_MOVE",
    "LAW_FOLLOWER",
    "LAW_FORCE_TRACKING",
    "LAW_NAMES",
    "LAW_NONE",
    "LAW_NORMAL",
    "LAW_PATH",
    "LAW_SPRING",
    "LINEAR_AXES",
    "N_AXES",
    "SAFETY_NAMES",
    "SAFETY_NAN",
    "SAFETY_NO_TF",
    "SAFETY_OK",
    "SAFETY_OVER_LIMIT",
    "SAFETY_STALE",
    "SAFETY_ZEROING",
    "End",
    "Exceeded",
    "Law",
    "Safety",
    "is_angular",
]

#: Axes of the control frame, in message order: three translations, then three rotations.
AXES: tuple[str, ...] = ("x", "y", "z", "rx", "ry", "rz")
N_AXES = 6
LINEAR_AXES = (0, 1, 2)
ANGULAR_AXES = (3, 4, 5)

class Law(IntEnum):
    """An axis's law: cartesian_impedance_msgs/ControlLaw TYPE_* (0-3), compliant_control_msgs/AxisLaw."""

    NONE = 0  # TYPE_UNKNOWN: the axis does not move
    FOLLOWER = 1
    SPRING = 2
    COMPLIANT_MOVE = 3
    FORCE_TRACKING = 4  # AxisLaw FORCE_TRACKING: through ConfigureLaws only (ControlLaw stops at 3)
    PATH = 5  # AxisLaw PATH: follows ~path_reference (a replay), ConfigureLaws only
    NORMAL = 6  # AxisLaw NORMAL: RX/RY turn the tool's axis onto the contact normal, ConfigureLaws only


class End(IntEnum):
    """Why a move ended on an axis: compliant_control_msgs/AxisState end conditions."""

    NONE = 0
    FT_VIOLATION = 1
    MAX_TRAVEL = 2
    DIFF_VIOLATION = 3
    NO_FT_DATA = 4
    EXTERNAL_STOP = 5
    OSCILLATION = 6
    PATH_LOST = 7
    PATH_ERROR = 8


class Exceeded(IntEnum):
    """What an axis does once the move ends on its force/torque limit (compliant_control_msgs/AxisLaw
    ACTION_*)."""

    STOP = 0  # hold (every axis holds when a move ends)
    MOVE_AWAY = 1  # back off along the measured force until below a fraction of the limit, then hold
    GRAVITY_COMPENSATION = 2  # become a follower with the axis's damping (hand-guiding)


class Safety(IntEnum):
    """The wrench's state this cycle: compliant_control_msgs/ContactControlStatus SAFETY_*."""

    OK = 0
    NAN = 1
    OVER_LIMIT = 2
    STALE = 3
    NO_TF = 4
    ZEROING = 5


LAW_NAMES: dict[int, str] = {
    Law.NONE: "none",
    Law.FOLLOWER: "follower",
    Law.SPRING: "spring",
    Law.COMPLIANT_MOVE: "compliant_move",
    Law.FORCE_TRACKING: "force_tracking",
    Law.PATH: "path",
    Law.NORMAL: "normal",
}
END_NAMES: dict[int, str] = {
    End.NONE: "none",
    End.FT_VIOLATION: "force/torque limit",
    End.MAX_TRAVEL: "max travel",
    End.DIFF_VIOLATION: "force jump",
    End.NO_FT_DATA: "no F/T data",
    End.EXTERNAL_STOP: "external stop",
    End.OSCILLATION: "oscillation",
    End.PATH_LOST: "path reference lost",
    End.PATH_ERROR: "path error",
}
EXCEEDED_ACTION_NAMES: dict[int, str] = {
    Exceeded.STOP: "stop",
    Exceeded.MOVE_AWAY: "move_away",
    Exceeded.GRAVITY_COMPENSATION: "gravity_compensation",
}
SAFETY_NAMES: dict[int, str] = {
    Safety.OK: "ok",
    Safety.NAN: "invalid wrench",
    Safety.OVER_LIMIT: "over global limit",
    Safety.STALE: "stale wrench",
    Safety.NO_TF: "missing transform",
    Safety.ZEROING: "zeroing the sensor",
}

# The members under their message constant names, as the rest of the stack uses them.
LAW_NONE, LAW_FOLLOWER, LAW_SPRING, LAW_COMPLIANT_MOVE, LAW_FORCE_TRACKING, LAW_PATH, LAW_NORMAL = Law
(END_NONE, END_FT_VIOLATION, END_MAX_TRAVEL, END_DIFF_VIOLATION, END_NO_FT_DATA, END_EXTERNAL_STOP,
 END_OSCILLATION, END_PATH_LOST, END_PATH_ERROR) = End
EXCEEDED_STOP, EXCEEDED_MOVE_AWAY, EXCEEDED_GRAVITY_COMPENSATION = Exceeded
SAFETY_OK, SAFETY_NAN, SAFETY_OVER_LIMIT, SAFETY_STALE, SAFETY_NO_TF, SAFETY_ZEROING = Safety


def is_angular(axis: int) -> bool:
    """True for rx, ry, rz (indices 3-5), whose units are Nm, rad and rad/s."""
    return axis >= 3
