"""controller_manager_msgs, franka_msgs and ur_dashboard_msgs (the subsets the emulated drivers serve),
control_msgs (named_poses' FollowJointTrajectory server) and nav_msgs (contact_tasks' ~follow_path) keep
the real packages' wire format: genmsg computes an md5sum from the definition text, so identical fields and
constants give the md5sums that the upstream packages' generated code carries."""

import pytest

pytest.importorskip("controller_manager_msgs.srv", reason="needs devel/setup.bash (make test sources it)")

from control_msgs.msg import (
    FollowJointTrajectoryFeedback,
    FollowJointTrajectoryGoal,
    FollowJointTrajectoryResult,
    JointTolerance,
)
from controller_manager_msgs import msg, srv
from franka_msgs.msg import ErrorRecoveryActionGoal, ErrorRecoveryGoal, ErrorRecoveryResult, FrankaState
from nav_msgs.msg import OccupancyGrid, Odometry, Path
from ur_dashboard_msgs.msg import RobotMode, SafetyMode

# From ros_control's generated code (Noetic, controller_manager_msgs 0.19/0.20) and franka_msgs.
MD5 = {
    srv.ListControllers: "1341feb2e63fa791f855565d0da950d8",
    srv.SwitchController: "b29a7abc673b2c54c14b54e50f8d06a5",
    msg.ControllerState: "aeb6b261d97793ab74099a3740245272",
    msg.HardwareInterfaceResources: "f25b55cbf1d1f76e82e5ec9e83f76258",
    # Empty goal and result: the md5 of the empty text.
    ErrorRecoveryGoal: "d41d8cd98f00b204e9800998ecf8427e",
    ErrorRecoveryResult: "d41d8cd98f00b204e9800998ecf8427e",
    # franka_ros 0.10's generated code (franka_msgs/FrankaState.h of rosserial builds): it covers Errors too.
    FrankaState: "431567d5df6caf4e4dd7385f25cb71ee",
    # Universal_Robots_ROS_Driver's generated code (ur_dashboard_msgs, Noetic).
    SafetyMode: "5da08725a63d4237bad689481131a84b",
    RobotMode: "73b72d58742c4889c47118411b03a3b4",
    # control_msgs 1.5 (Noetic), its generated code in rosserial and ROS.NET builds; the goal's md5 covers
    # JointTolerance's too (genmsg hashes a field's type by its md5).
    FollowJointTrajectoryGoal: "69636787b6ecbde4d61d711979bc7ecb",
    FollowJointTrajectoryResult: "493383b18409bfb604b4e26c676401d2",
    FollowJointTrajectoryFeedback: "10817c60c2486ef6b33e97dcd87f4474",
    JointTolerance: "f544fe9c16cf04547e135dd6063ff5be",
    # nav_msgs 1.13 (Noetic), as rosbag's connection headers of recorded paths and odometry carry them.
    Path: "6227e2b7e9cce15051f669a5e197bbf7",
    Odometry: "cd5e73d190d741a2f92e81eda573aca7",
    OccupancyGrid: "3381f2d731d4076ec5c71b0759edbe4e",
}


@pytest.mark.parametrize("cls", list(MD5), ids=lambda c: c._type)
def test_md5sum_matches_the_real_package(cls):
    assert cls._md5sum == MD5[cls]


def test_fields_and_constants():
    assert srv.SwitchControllerRequest.BEST_EFFORT == 1 and srv.SwitchControllerRequest.STRICT == 2
    assert srv.SwitchControllerRequest.__slots__ == [
        "start_controllers", "stop_controllers", "strictness", "start_asap", "timeout"]
    assert srv.ListControllersResponse.__slots__ == ["controller"]
    assert msg.ControllerState.__slots__ == ["name", "state", "type", "claimed_resources"]
    assert ErrorRecoveryActionGoal._type == "franka_msgs/ErrorRecoveryActionGoal"
    assert FrankaState.ROBOT_MODE_MOVE == 2 and FrankaState.ROBOT_MODE_REFLEX == 4
    assert len(FrankaState().q) == 7 and FrankaState().current_errors.cartesian_reflex is False
    assert ErrorRecoveryActionGoal.__slots__ == ["header", "goal_id", "goal"]
    assert SafetyMode.PROTECTIVE_STOP == 3 and SafetyMode.NORMAL == 1 and SafetyMode.__slots__ == ["mode"]
    assert RobotMode.RUNNING == 7 and RobotMode.NO_CONTROLLER == -1 and RobotMode.__slots__ == ["mode"]
