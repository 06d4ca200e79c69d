"""named_poses' FollowJointTrajectory server on the simulated UR5: a planned trajectory in free space ends
within its goal tolerance; one that runs the tool down into the block stops at the contact force limit and
says so; a cancel stops the arm where it is; one faster than the collaborative speed cap is refused and
nothing moves."""

from __future__ import annotations

import numpy as np
import pytest

pytest.importorskip("control_msgs.msg", reason="needs devel/setup.bash (make test sources it)")

import actionlib
import rospy
from compliant_control_msgs.srv import MoveToNamedPose
from control_msgs.msg import (
    FollowJointTrajectoryAction,
    FollowJointTrajectoryGoal,
    FollowJointTrajectoryResult,
)
from geometry_msgs.msg import PoseStamped
from harness.launch import run_launch
from harness.waiting import Collector, wait_until
from jog_arm.kinematics import ArmModel
from sensor_msgs.msg import JointState
from trajectory_msgs.msg import JointTrajectoryPoint

JOINTS = ["shoulder_pan_joint", "shoulder_lift_joint", "elbow_joint", "wrist_1_joint", "wrist_2_joint",
          "wrist_3_joint"]
BLOCK_TOP = 0.13  # [m] ur5_custom's block (sim.yaml); the start pose's tool tip is 0.07 above it


@pytest.fixture(scope="module")
def arm(ros_node):
    with run_launch("ur5_custom", "sim.launch") as h:
        h.wait_for_service("/named_poses/move_to", timeout=60)
        # jog_arm's dynamic_reconfigure server writes its values to the parameter server as it starts: a
        # region set before that (the speed-cap test) would be overwritten.
        h.wait_for_service("/jog_arm_server/set_parameters", timeout=60)
        client = actionlib.SimpleActionClient("/named_poses/follow_joint_trajectory",
                                              FollowJointTrajectoryAction)
        assert client.wait_for_server(rospy.Duration(30.0))
        tip = Collector("/mujoco_driver/eef_pose", PoseStamped)
        states = Collector("/joint_states", JointState)
        model = ArmModel(rospy.get_param("/robot_description"), "tool_tip", JOINTS)
        try:
            tip.wait_for(1, timeout=20)
            yield type("Arm", (), {"client": client, "tip": tip, "states": states, "model": model})
        finally:
            tip.close()
            states.close()


def _joints(arm) -> np.ndarray:
    at = dict(zip(arm.states.last().name, arm.states.last().position, strict=False))
    return np.array([at[j] for j in JOINTS])


def _z(arm) -> float:
    return arm.tip.last().pose.position.z


def _line(arm, q0: np.ndarray, dz: float, seconds: float, points: int = 20) -> FollowJointTrajectoryGoal:
    """A trajectory that moves the tool tip `dz` [m] along the base's z in `seconds`, its orientation kept
    (damped least squares on the tip Jacobian), joints in reverse order (the server reorders them)."""
    goal = FollowJointTrajectoryGoal()
    goal.trajectory.joint_names = JOINTS[::-1]
    q = q0.copy()
    goal.trajectory.points.append(JointTrajectoryPoint(positions=q[::-1].tolist(),
                                                       time_from_start=rospy.Duration(0.0)))
    for i in range(1, points + 1):
        for _ in range(5):
            J = arm.model.jacobian(q)
            step = np.zeros(6)
            step[2] = dz / points / 5
            q = q + J.T @ np.linalg.solve(J @ J.T + 1e-6 * np.eye(6), step)
        goal.trajectory.points.append(JointTrajectoryPoint(
            positions=q[::-1].tolist(), time_from_start=rospy.Duration.from_sec(seconds * i / points)))
    return goal


def _start(arm) -> np.ndarray:
    assert rospy.ServiceProxy("/named_poses/move_to", MoveToNamedPose)(name="start").success
    wait_until(lambda: _still(arm) and abs(_z(arm) - 0.2) < 0.002, 10, "the arm at rest at the start pose")
    return _joints(arm)


def _still(arm) -> bool:
    """The tool tip moved less than 0.1 mm over the last 0.2 s (20 poses at 100 Hz)."""
    zs = [m.pose.position.z for m in list(arm.tip.msgs)[-20:]]
    return len(zs) == 20 and max(zs) - min(zs) < 0.0001


def test_a_free_trajectory_ends_within_its_goal_tolerance(arm):
    q0 = _start(arm)
    z0 = _z(arm)
    assert arm.client.send_goal_and_wait(_line(arm, q0, 0.05, 2.5), rospy.Duration(20.0))
    result = arm.client.get_result()
    assert result.error_code == FollowJointTrajectoryResult.SUCCESSFUL, result.error_string
    assert result.error_string.startswith("done: 21 points in 2.50 s")
    assert _z(arm) == pytest.approx(z0 + 0.05, abs=0.002)


def test_a_trajectory_into_the_block_stops_at_the_force_limit(arm):
    q0 = _start(arm)
    arm.client.send_goal(_line(arm, q0, -0.10, 10.0))  # 1 cm/s; the block 7 cm down
    assert arm.client.wait_for_result(rospy.Duration(30.0))
    result = arm.client.get_result()
    print(f"\ninto the block: {result.error_string}; tool tip z {_z(arm):.4f} m")
    assert result.error_code == FollowJointTrajectoryResult.PATH_TOLERANCE_VIOLATED
    assert "stopped at the contact force limit" in result.error_string
    stopped = _z(arm)
    assert BLOCK_TOP - 0.002 < stopped < BLOCK_TOP + 0.002  # on the block, not 3 cm into it
    t0 = arm.tip.last().header.stamp.to_sec()
    wait_until(lambda: arm.tip.last().header.stamp.to_sec() > t0 + 1.0, 10, "a second")
    assert abs(_z(arm) - stopped) < 0.0005  # it holds there


def test_a_cancel_stops_the_arm_where_it_is(arm):
    q0 = _start(arm)
    arm.client.send_goal(_line(arm, q0, 0.08, 8.0))
    wait_until(lambda: _z(arm) > 0.21, 10, "the tool moving up")
    arm.client.cancel_goal()
    assert arm.client.wait_for_result(rospy.Duration(10.0))
    assert arm.client.get_state() == actionlib.GoalStatus.PREEMPTED
    assert arm.client.get_result().error_string.startswith("cancelled at")
    cancelled = _z(arm)
    t0 = arm.tip.last().header.stamp.to_sec()
    wait_until(lambda: arm.tip.last().header.stamp.to_sec() > t0 + 1.0, 10, "a second")
    assert abs(_z(arm) - cancelled) < 0.002 and _z(arm) < 0.26


def test_a_trajectory_faster_than_the_speed_cap_is_refused_and_nothing_moves(arm):
    q0 = _start(arm)
    z0 = _z(arm)
    rospy.set_param("/jog_arm_server/collaborative_region", "face")  # named_poses reads it per goal
    try:  # 0.3 m/s: within the hand's cap (1.4 m/s and more), over the face's
        assert arm.client.send_goal_and_wait(_line(arm, q0, 0.3, 1.0), rospy.Duration(20.0))
    finally:
        rospy.set_param("/jog_arm_server/collaborative_region", "hand")
    result = arm.client.get_result()
    assert result.error_code == FollowJointTrajectoryResult.INVALID_GOAL
    print(f"\ntoo fast: {result.error_string}")
    assert "faster than the collaborative speed cap" in result.error_string, result.error_string
    assert abs(_z(arm) - z0) < 0.0005
