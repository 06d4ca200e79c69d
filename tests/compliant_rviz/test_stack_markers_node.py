"""stack_markers on its own: a replay's path reference and the tool's way along it become the green and
yellow lines, the status's laws the text, and nothing is drawn for a push that ended."""

from __future__ import annotations

import pytest
from harness.launch import run_node
from harness.rviz import named
from harness.waiting import Collector, wait_until

pytest.importorskip("compliant_control_msgs.msg", reason="needs devel/setup.bash (make test sources it)")


def test_a_replay_draws_its_reference_and_the_tools_path(ros_node):
    import tf2_ros
    from compliant_control_msgs.msg import AxisState, ContactControlStatus, PathReference
    from geometry_msgs.msg import TransformStamped, WrenchStamped
    from visualization_msgs.msg import MarkerArray

    rospy = ros_node
    ns = "/markers_test_cc"
    tf = tf2_ros.TransformBroadcaster()
    status_pub = rospy.Publisher(f"{ns}/status", ContactControlStatus, queue_size=1, latch=True)
    ref_pub = rospy.Publisher(f"{ns}/path_reference", PathReference, queue_size=10)
    push_pub = rospy.Publisher("/markers_test_push", WrenchStamped, queue_size=1, latch=True)
    status = ContactControlStatus(safety_name="ok")
    status.header.frame_id = "base_link"
    status.axes = [AxisState(axis=a, law_name="none", end_condition_name="none")
                   for a in ("x", "y", "rx", "ry", "rz")]
    status.axes.insert(2, AxisState(axis="z", law_name="force_tracking", force=10.1, velocity=-0.0002,
                                    end_condition_name="none"))
    status_pub.publish(status)
    push_pub.publish(WrenchStamped())  # a push that ended: zeros

    x = [0.4]

    def tool_tf() -> TransformStamped:
        t = TransformStamped()
        t.header.stamp = rospy.Time.now()
        t.header.frame_id, t.child_frame_id = "base_link", "tool_tip"
        t.transform.translation.x, t.transform.translation.z = x[0], 0.1
        t.transform.rotation.w = 1.0
        return t

    markers = Collector("/stack_markers_test/markers", MarkerArray)
    params = {"contact_control": ns, "base_frame": "base_link", "tip_frame": "tool_tip",
              "push_topic": "/markers_test_push", "scene_config": "''"}
    try:
        with run_node("compliant_rviz", "stack_markers", params=params, name="stack_markers_test"):
            pace = rospy.Rate(100.0)  # the replay streams its reference at 100 Hz
            for k in range(400):  # a 4 cm line at 1 cm/s, 100 Hz: the reference and the tool along it
                if rospy.is_shutdown():
                    break
                x[0] = 0.4 - 0.0001 * k
                tf.sendTransform(tool_tf())
                ref = PathReference()
                ref.header.frame_id = "base_link"
                ref.pose.position.x, ref.pose.position.z = x[0], 0.1
                ref.pose.orientation.w = 1.0
                ref_pub.publish(ref)
                if k > 50 and markers.msgs and named(markers.last(), "tool path") is not None:
                    break
                pace.sleep()

            def drawn() -> bool:
                last = markers.last()
                return bool(last and named(last, "reference path") and named(last, "tool path"))

            wait_until(drawn, 10, "both paths")
            last = markers.last()
            reference, tool = named(last, "reference path"), named(last, "tool path")
            assert len(reference.points) >= 2 and len(tool.points) >= 2
            assert all(abs(p.z - 0.1) < 1e-9 for p in reference.points + tool.points)
            assert reference.points[-1].x < reference.points[0].x  # along -X, as sent
            assert named(last, "laws").text.startswith("z: force_tracking  +10.1 N  -0.2 mm/s")
            assert named(last, "push") is None and named(last, "obstacle") is None
    finally:
        markers.close()
