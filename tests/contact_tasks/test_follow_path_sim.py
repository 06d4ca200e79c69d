"""End to end: task_server's ~follow_path on the simulated UR5 with a ball-end tool over parts that are not
where the paths were planned: a 0.3 m path over the nominal cylinder's top at 20 mm/s pressing 10 N, given as
a nav_msgs/Path in another tf frame, and 80 mm down the tilted plane. The results' figures, and the tool's
axis against the driver's ground truth; a goal that cannot be run is refused and nothing moves."""

from __future__ import annotations

import math

import numpy as np
import pytest

pytest.importorskip("compliant_control_msgs.msg", reason="needs devel/setup.bash (make test sources it)")

import actionlib
import dynamic_reconfigure.client
import rospy
import tf2_ros
from compliant_control_msgs.msg import FollowPathAtForceAction, FollowPathAtForceGoal
from compliant_control_msgs.srv import MoveToNamedPose
from contact_control.frames import matrix_quaternion, quaternion_matrix
from geometry_msgs.msg import Pose, PoseStamped
from harness.waiting import Collector
from thesis_demos.surfaces import cylinder_normal, cylinder_path

from .task_stack import task_stack

RADIUS = 0.25  # [m] mujoco_driver's cylinder
OFFSET = (0.006, -0.004, 0.007)  # [m] where the cylinder is, off its nominal place
NOMINAL_TOP = (0.60, 0.109, 0.13)  # ur5_custom's block top centre: where the path is planned
DOWN = np.diag([1.0, -1.0, -1.0])  # ur5_custom's start orientation: the tool's z down
# [rad] the path's middle, from the top toward the base: the UR5's far side, 0.6 rad past the top, slows
# jog_arm near a singularity (condition number 8 at x 0.74 m)
MIDDLE = -0.15


def _pose(row: list[float]) -> Pose:
    pose = Pose()
    pose.position.x, pose.position.y, pose.position.z = row[:3]
    o = pose.orientation
    o.x, o.y, o.z, o.w = row[3:]
    return pose


def _in_frame(buffer: tf2_ros.Buffer, frame: str, rows: list[list[float]]) -> list[Pose]:
    """base_link poses expressed in `frame` (what a planner working in that frame would send)."""
    t = buffer.lookup_transform(frame, "base_link", rospy.Time(0), rospy.Duration(5.0)).transform
    R = np.asarray(quaternion_matrix(t.rotation.x, t.rotation.y, t.rotation.z, t.rotation.w))
    p = np.array([t.translation.x, t.translation.y, t.translation.z])
    out = []
    for row in rows:
        turned = R @ np.asarray(quaternion_matrix(*row[3:]))
        out.append(_pose([*(R @ np.asarray(row[:3]) + p), *matrix_quaternion(turned.tolist())]))
    return out


def _tip_and_axis(msg: PoseStamped) -> tuple[np.ndarray, np.ndarray]:
    p, q = msg.pose.position, msg.pose.orientation
    return np.array([p.x, p.y, p.z]), np.asarray(quaternion_matrix(q.x, q.y, q.z, q.w))[:, 2]


def test_a_path_over_an_offset_cylinder_is_run_at_10_n_with_the_tool_normal(ros_node):
    offset = f"[{OFFSET[0]}, {OFFSET[1]}, {OFFSET[2]}]"
    args = {"fixture": "cylinder", "tool": "ball", "surface_offset": offset}
    with task_stack(args) as (h, _client, tool):
        assert rospy.ServiceProxy("/named_poses/move_to", MoveToNamedPose)(name="start").success
        truth = rospy.get_param("/mujoco_driver/surface")  # the driver's ground truth, for judging only
        dynamic_reconfigure.client.Client("/contact_control_node", timeout=20).update_configuration(
            {"normal_friction": 0.3})  # the fixture's friction
        client = actionlib.SimpleActionClient("/task_server/follow_path", FollowPathAtForceAction)
        assert client.wait_for_server(rospy.Duration(30.0))

        # a goal that cannot be run: refused with the field, and the arm stays
        start = tool()
        bad = FollowPathAtForceGoal(speed=0.02, force=10.0)
        bad.poses.header.frame_id = "base_link"
        bad.poses.poses = [_pose([0.6, 0.1, 0.13, 1.0, 0.0, 0.0, 0.0])]
        client.send_goal(bad)
        assert client.wait_for_result(rospy.Duration(20.0))
        refused = client.get_result()
        assert refused.outcome == "refused" and "at least two poses" in refused.message, refused.message
        assert np.allclose(tool()[:3], start[:3], atol=5e-4)

        buffer = tf2_ros.Buffer()
        listener = tf2_ros.TransformListener(buffer)  # noqa: F841 (fills the buffer)
        planned = cylinder_path(NOMINAL_TOP, RADIUS, 0.3, DOWN, middle=MIDDLE)
        goal = FollowPathAtForceGoal(speed=0.02, force=10.0)
        goal.path.header.frame_id = "base"  # UR's base frame: base_link turned half a turn about z
        goal.path.poses = [PoseStamped(pose=p) for p in _in_frame(buffer, "base", planned)]
        pose = Collector("/mujoco_driver/eef_pose", PoseStamped)
        following: list[float] = []

        def feedback(f) -> None:
            if f.step == "follow":
                following.append(rospy.get_time())

        try:
            client.send_goal(goal, feedback_cb=feedback)
            assert client.wait_for_result(rospy.Duration(120.0))
            result = client.get_result()
        finally:
            pose.close()
        end = tool()
        h.stop()
    print(f"\nfollow_path: {result.outcome}: {result.message}; force RMS error {result.force_rms_error:.2f} "
          f"N, max {result.force_max:.1f} N, contact {result.contact_fraction:.3f}, angle (force) RMS "
          f"{result.normal_angle_rms:.2f} max {result.normal_angle_max:.2f} deg, lateral RMS "
          f"{result.lateral_error_rms * 1e3:.2f} max {result.lateral_error_max * 1e3:.2f} mm, "
          f"{result.duration:.1f} s")
    assert result.success and result.message == "ran the path's 0.300 m", result.message
    assert result.length == pytest.approx(0.3, abs=0.002)
    assert result.duration == pytest.approx(15.5, abs=0.3)  # 0.3 m at 20 mm/s, 0.5 s to speed up and down
    assert result.force_rms_error <= 1.5 and result.force_max <= 20.0 and result.contact_fraction >= 0.98
    assert result.normal_angle_rms <= 3.0 and result.lateral_error_max <= 0.002
    # against the truth: the tool's axis on the real cylinder's normal under the tip
    angles = []
    for m in pose.msgs:
        if following[0] < m.header.stamp.to_sec() < following[-1]:
            tip, axis = _tip_and_axis(m)
            n = cylinder_normal(truth["top"], RADIUS, tip)
            angles.append(math.degrees(math.acos(float(np.clip(-axis @ n, -1.0, 1.0)))))
    angles = np.array(angles)
    rms = math.sqrt(float(np.mean(angles**2)))
    print(f"tool's axis to the true normal under the tip: RMS {rms:.2f}, max {angles.max():.2f} deg")
    assert len(angles) > 100 and rms <= 3.0 and angles.max() <= 8.0
    centre = np.asarray(truth["top"]) - (0.0, 0.0, RADIUS)
    over = math.atan2(end[0] - centre[0], end[2] - centre[2])  # where the tool ended on the real cylinder
    assert over == pytest.approx(MIDDLE + 0.6, abs=0.03)  # the path's end, 0.15 m of arc past its middle


def test_a_path_down_a_tilted_plane_keeps_the_force_along_the_tool_and_the_tool_normal(ros_node):
    """The driver's `tilted` block (15 degrees about y, 4/-3/6 mm off): an 80 mm path down its slope planned
    on the nominal plane, pressing 8 N, with the tool on the plane's normal throughout."""
    tilt, offset = 0.2618, (0.004, -0.003, 0.006)
    slope = np.array([[math.cos(tilt), 0.0, math.sin(tilt)], [0.0, 1.0, 0.0],
                      [-math.sin(tilt), 0.0, math.cos(tilt)]])  # turned about y
    centre = np.array([0.60, 0.109, 0.065]) + slope @ (0.0, 0.0, 0.065)  # ur5_custom's block, top face centre
    along = slope[:, 0]
    turned = slope @ DOWN
    quaternion = matrix_quaternion(turned.tolist())
    planned = [[*(centre + s * along), *quaternion] for s in np.linspace(-0.04, 0.04, 9)]
    args = {"fixture": "tilted", "tool": "ball", "surface_offset": f"[{offset[0]}, {offset[1]}, {offset[2]}]"}
    with task_stack(args) as (h, _client, _tool):
        assert rospy.ServiceProxy("/named_poses/move_to", MoveToNamedPose)(name="start").success
        truth = rospy.get_param("/mujoco_driver/surface")
        assert truth["kind"] == "tilted"
        dynamic_reconfigure.client.Client("/contact_control_node", timeout=20).update_configuration(
            {"normal_friction": truth["friction"]})
        client = actionlib.SimpleActionClient("/task_server/follow_path", FollowPathAtForceAction)
        assert client.wait_for_server(rospy.Duration(30.0))
        goal = FollowPathAtForceGoal(speed=0.01, force=8.0)
        goal.poses.header.frame_id = "base_link"
        goal.poses.poses = [_pose(row) for row in planned]
        pose = Collector("/mujoco_driver/eef_pose", PoseStamped)
        following: list[float] = []
        try:
            client.send_goal(goal, feedback_cb=lambda f: following.append(rospy.get_time())
                             if f.step == "follow" else None)
            assert client.wait_for_result(rospy.Duration(90.0))
            result = client.get_result()
        finally:
            pose.close()
        h.stop()
    print(f"\nfollow_path (tilted): {result.outcome}: {result.message}; force RMS error "
          f"{result.force_rms_error:.2f} N, max {result.force_max:.1f} N, contact "
          f"{result.contact_fraction:.3f}, angle (force) RMS {result.normal_angle_rms:.2f} deg, lateral max "
          f"{result.lateral_error_max * 1e3:.2f} mm")
    assert result.success, result.message
    assert result.force_rms_error <= 1.5 and result.force_max <= 16.0 and result.contact_fraction >= 0.98
    assert result.lateral_error_max <= 0.002
    normal = slope[:, 2]  # the plane's normal (an offset moves the plane, it does not turn it)
    angles = np.array([math.degrees(math.acos(float(np.clip(-_tip_and_axis(m)[1] @ normal, -1.0, 1.0))))
                       for m in pose.msgs if following[0] < m.header.stamp.to_sec() < following[-1]])
    rms = math.sqrt(float(np.mean(angles**2)))
    print(f"tool's axis to the plane's normal: RMS {rms:.2f}, max {angles.max():.2f} deg")
    assert len(angles) > 100 and rms <= 3.0 and angles.max() <= 8.0
