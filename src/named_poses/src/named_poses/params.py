"""The named_pose_server's private parameters, each declared once (no ROS): `PARAMETERS` validates them at
start-up and generates the README's table.

Without `~config`, `poses`, `max_velocity` and `max_acceleration` are the node's private parameters, with
them the keys of the file; `poses.NamedPoses.from_dict` checks them against the URDF (these defaults apply).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

from compliant_common.schema import SchemaError, param, schema_of

__all__ = ["FILE_KEYS", "PARAMETERS", "NamedPoseSettings", "load_settings"]

#: The keys of a robot package's named_poses.yaml (also private parameters when `~config` is empty).
FILE_KEYS = ("poses", "max_velocity", "max_acceleration")


@dataclass(frozen=True)
class NamedPoseSettings:
    """The node's parameters (name, type, default, unit, range, doc declared here)."""

    config: str = param(
        "",
        doc="path of the robot package's `named_poses.yaml` (`poses`, `max_velocity`, `max_acceleration`), "
        "read by the node itself: loaded as parameters, a dict would merge with the poses a previous robot "
        "left on the same master. Empty: the same keys as private parameters",
    )
    poses: Mapping[str, Any] | None = param(
        None, type="mapping", optional=True, unit="rad",
        doc="name -> {joint: angle}; every pose names the same joints, each within its URDF limits",
    )
    max_velocity: Any = param(
        0.5, type="any", unit="rad/s", shown_range="> 0, one number or {joint: value}",
        doc="joint-space velocity limit of a move (capped by the URDF's)",
    )
    max_acceleration: Any = param(
        1.0, type="any", unit="rad/s^2", shown_range="> 0, one number or {joint: value}",
        doc="joint-space acceleration limit of a move",
    )
    goal_tolerance: float = param(
        0.01, unit="rad, m", gt=0.0, doc="`~move_to` succeeds once every joint is this close to the pose"
    )
    settle_time: float = param(
        3.0, unit="s", ge=0.0, doc="`~move_to` fails this long after the planned end if not arrived"
    )
    state_wait: float = param(
        2.0, unit="s", ge=0.0,
        doc="`~move_to` waits this long for a joint state of every pose joint, and for the driver to "
            "subscribe to the trajectory topic, before it refuses",
    )
    trajectory_topic: str = param(
        "arm_controller/command", nonempty=True, doc="trajectory_msgs/JointTrajectory output (the driver's)"
    )
    joint_states_topic: str = param("joint_states", nonempty=True, doc="sensor_msgs/JointState input")
    controller_manager: str = param(
        "controller_manager",
        doc="a ros_control controller manager's namespace: if it serves list_controllers and the controller "
        "of `trajectory_topic` (`<controller>/command`) is not running, a move switches it on, stopping the "
        "running controllers that claim its joints, and switches back afterwards; empty: never switch",
    )
    jog_arm: str = param(
        "jog_arm_server",
        doc="jog_arm's namespace: if it serves `pause`, a move pauses it first (its commands would replace "
        "the trajectory; the answer comes once it is silent) and resumes it afterwards, unless it was "
        "paused already; empty: never pause",
    )
    contact_control_status: str = param(
        "contact_control_node/status", nonempty=True,
        doc="compliant_control_msgs/ContactControlStatus input: no move while a contact move runs",
    )
    # ~follow_joint_trajectory (README, FollowJointTrajectory)
    contact_wrench: str = param(
        "contact_control_node/contact_wrench", nonempty=True,
        doc="geometry_msgs/WrenchStamped input while a trajectory runs: contact_control's contact force",
    )
    trajectory_force_limit: float = param(
        20.0, unit="N", gt=0.0, doc="a trajectory stops when the contact force reaches this "
        "(PATH_TOLERANCE_VIOLATED; jog_arm's contact guard stops a jog at 20 N too)",
    )
    trajectory_path_tolerance: float = param(
        0.0, unit="rad or m", ge=0.0, doc="a joint further than this from where the trajectory should be has "
        "it stopped, unless the goal gives its own; 0: none (ros_control's default)",
    )
    trajectory_goal_time: float = param(
        1.0, unit="s", gt=0.0, doc="how long after the last point the arm may take to get within the goal "
        "tolerance (`goal_tolerance` unless the goal gives its own), unless the goal gives its own",
    )
    trajectory_feedback_rate: float = param(10.0, unit="Hz", gt=0.0, le=100.0, doc="feedback while it runs")


PARAMETERS = schema_of(NamedPoseSettings)


def load_settings(params: Mapping[str, Any]) -> NamedPoseSettings:
    """Settings from the node's private parameters (`rospy.get_param("~")`).

    Raises:
        ValueError: An unknown key (naming the closest valid one) or a bad value, naming the key.
    """
    try:
        return PARAMETERS.build(NamedPoseSettings, PARAMETERS.load(params, prefix="~"))
    except SchemaError as err:
        raise ValueError(err.named("~")) from None
