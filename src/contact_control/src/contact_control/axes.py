"""Axis names and the integer codes shared with the messages.

The values equal the constants of `cartesian_impedance_msgs/ControlLaw`, `compliant_control_msgs/AxisState`
and `compliant_control_msgs/ContactControlStatus`, so the node copies them into messages unchanged. They are
plain ints (not enums) because the control loop compares them every cycle.
"""

from __future__ import annotations

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
    "is_angular",
]

#: Axes of the control frame, in message order: three translations, then three rotations.
AXES: tuple[str, ...] = ("x", "y", "z", "rx", "ry", "rz")
N_AXES = 6
LINEAR_AXES = (0, 1, 2)
ANGULAR_AXES = (3, 4, 5)

# cartesian_impedance_msgs/ControlLaw TYPE_*
LAW_NONE = 0  # TYPE_UNKNOWN: the axis does not move
LAW_FOLLOWER = 1
LAW_SPRING = 2
LAW_COMPLIANT_MOVE = 3
# compliant_control_msgs/AxisLaw FORCE_TRACKING: offered through ConfigureLaws only (ControlLaw stops at 3)
LAW_FORCE_TRACKING = 4
# compliant_control_msgs/AxisLaw PATH: follows ~path_reference (a replay), ConfigureLaws only
LAW_PATH = 5
LAW_NAMES = {
    LAW_NONE: "none",
    LAW_FOLLOWER: "follower",
    LAW_SPRING: "spring",
    LAW_COMPLIANT_MOVE: "compliant_move",
    LAW_FORCE_TRACKING: "force_tracking",
    LAW_PATH: "path",
}

# compliant_control_msgs/AxisState end conditions
END_NONE = 0
END_FT_VIOLATION = 1
END_MAX_TRAVEL = 2
END_DIFF_VIOLATION = 3
END_NO_FT_DATA = 4
END_EXTERNAL_STOP = 5
END_OSCILLATION = 6
END_PATH_LOST = 7
END_PATH_ERROR = 8
END_NAMES = {
    END_NONE: "none",
    END_FT_VIOLATION: "force/torque limit",
    END_MAX_TRAVEL: "max travel",
    END_DIFF_VIOLATION: "force jump",
    END_NO_FT_DATA: "no F/T data",
    END_EXTERNAL_STOP: "external stop",
    END_OSCILLATION: "oscillation",
    END_PATH_LOST: "path reference lost",
    END_PATH_ERROR: "path error",
}

# compliant_control_msgs/AxisLaw ACTION_*: what an axis does once the move ends on a force/torque limit
EXCEEDED_STOP = 0  # hold (every axis holds when a move ends)
EXCEEDED_MOVE_AWAY = 1  # back off along the measured force until below a fraction of the limit, then hold
EXCEEDED_GRAVITY_COMPENSATION = 2  # become a follower with the axis's damping (hand-guiding)
EXCEEDED_ACTION_NAMES = {
    EXCEEDED_STOP: "stop",
    EXCEEDED_MOVE_AWAY: "move_away",
    EXCEEDED_GRAVITY_COMPENSATION: "gravity_compensation",
}

# compliant_control_msgs/ContactControlStatus SAFETY_*
SAFETY_OK = 0
SAFETY_NAN = 1
SAFETY_OVER_LIMIT = 2
SAFETY_STALE = 3
SAFETY_NO_TF = 4
SAFETY_ZEROING = 5
SAFETY_NAMES = {
    SAFETY_OK: "ok",
    SAFETY_NAN: "invalid wrench",
    SAFETY_OVER_LIMIT: "over global limit",
    SAFETY_STALE: "stale wrench",
    SAFETY_NO_TF: "missing transform",
    SAFETY_ZEROING: "zeroing the sensor",
}


def is_angular(axis: int) -> bool:
    """True for rx, ry, rz (indices 3-5), whose units are Nm, rad and rad/s."""
    return axis >= 3
