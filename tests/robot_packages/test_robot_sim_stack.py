"""End to end, per robot: `roslaunch <robot>_custom sim.launch` brings up the whole stack, a twist into
jog_arm's input moves the tool tip that way, contact_control's follower makes the tool give way to a simulated
push, and everything shuts down cleanly."""

from __future__ import annotations

import contextlib
import os
import xmlrpc.client

import numpy as np
import pytest

pytest.importorskip("cartesian_impedance_msgs.srv", reason="needs devel/setup.bash (make test sources it)")

from cartesian_impedance_msgs.msg import ControlLaw
from cartesian_impedance_msgs.srv import ConfigureForceControl, ConfigureForceControlRequest
from compliant_control_msgs.msg import ContactControlStatus, JogStatus
from compliant_control_msgs.srv import PushEEF, PushEEFRequest
from geometry_msgs.msg import PoseStamped, TwistStamped, WrenchStamped
from harness.launch import run_launch
from harness.waiting import Collector, wait_until
from sensor_msgs.msg import JointState
from std_srvs.srv import Trigger

BASE_FRAME = {"ur5_custom": "base_link", "panda_custom": "panda_link0"}
TOPICS = ("/joint_states", "/wrench", "/tf", "/mujoco_driver/eef_pose")
SERVICES = ("/configure_cartesian_impedance", "/configure_cartesian_impedance_blocking",
            "/contact_control_node/tare", "/contact_control_node/stop", "/jog_arm_server/pause",
            "/mujoco_driver/push", "/mujoco_driver/reset")
NODES = ("/mujoco_driver", "/control_stack", "/jog_arm_server", "/contact_control_node",
         "/robot_state_publisher")


MESSAGES = {"/mujoco_driver/eef_pose": PoseStamped, "/joint_states": JointState, "/wrench": WrenchStamped,
            "/contact_control_node/status": ContactControlStatus}


@contextlib.contextmanager
def _clients(rospy, *topics: str):
    """Collectors on `topics` (each holding a first message), then a publisher into jog_arm's input (the
    keyboard's path) once jog_arm listens; all closed on exit. Few subscribers: on 2 cores this process's
    load delays the stack's messages."""
    collectors = [Collector(topic, MESSAGES[topic]) for topic in topics]
    twist_pub = rospy.Publisher("/jog_arm_server/delta_jog_cmds", TwistStamped, queue_size=1,
                                tcp_nodelay=True)
    try:
        for c in collectors:
            c.wait_for(1, timeout=20)
        wait_until(lambda: twist_pub.get_num_connections() > 0, 10, "jog_arm to subscribe to its input")
        yield (*collectors, twist_pub)
    finally:
        for c in collectors:
            c.close()
        twist_pub.unregister()


def _registered_nodes() -> set[str]:
    code, _, state = xmlrpc.client.ServerProxy(os.environ["ROS_MASTER_URI"]).getSystemState("/probe")
    assert code == 1
    return {node for kind in state for _, nodes in kind for node in nodes}


# The demos run both robots in one process (the default); here each robot also runs the other layout.
@pytest.mark.parametrize("robot, single_process", [("panda_custom", False), ("ur5_custom", True)])
def test_sim_stack_comes_up_jogs_follows_a_push_and_shuts_down(ros_node, robot, single_process):
    rospy = ros_node
    with run_launch(robot, "sim.launch", args={"single_process": str(single_process).lower()}) as h:
        for topic in TOPICS:
            h.wait_for_topic(topic, timeout=40)
        for service in SERVICES:
            h.wait_for_service(service, timeout=40)
        clients = _clients(rospy, "/mujoco_driver/eef_pose", "/joint_states", "/contact_control_node/status")
        with clients as (pose, joints, cc_status, twist_pub):
            rospy.wait_for_message("/wrench", WrenchStamped, timeout=10)
            rospy.wait_for_message("/jog_arm_server/status", JogStatus, timeout=10)

            def tip() -> np.ndarray:
                p = pose.last().pose.position
                return np.array([p.x, p.y, p.z])

            def settle() -> None:
                wait_until(lambda: np.max(np.abs(joints.last().velocity)) < 2e-3, 10, "the arm to stop")

            # 1. A twist into jog_arm's input (the keyboard's path): 5 cm/s along -X of the base frame.
            start = tip()
            twist = TwistStamped()
            twist.header.frame_id = BASE_FRAME[robot]
            twist.twist.linear.x = -0.05
            rate = rospy.Rate(50)
            while start[0] - tip()[0] < 0.02:
                assert h.proc.poll() is None, h.output()[-3000:]
                twist.header.stamp = rospy.Time.now()
                twist_pub.publish(twist)
                rate.sleep()  # the sender's rate, not a wait for a result
            moved = tip() - start
            assert np.all(np.abs(moved[1:]) < 0.25 * abs(moved[0])), f"tool tip left the X line: {moved}"
            settle()
            status = rospy.wait_for_message("/jog_arm_server/status", JogStatus, timeout=10)
            assert status.code in (JogStatus.NO_WARNING, JogStatus.STALE_COMMAND), status

            # 2. contact_control: a follower on X (b = 200 N s/m: 5 cm/s for 10 N) gives way to a push.
            req = ConfigureForceControlRequest()
            req.cart_impedance_params.damping.translational.x = 200.0
            req.direction_control_laws.x.type = ControlLaw.TYPE_FOLLOWER
            configure = rospy.ServiceProxy("/configure_cartesian_impedance", ConfigureForceControl)
            assert configure(req).success, h.output()[-3000:]
            wait_until(lambda: cc_status.last().move_active, 5, "the follower to be active")
            before = tip()
            push = PushEEFRequest(duration=0.6)
            push.wrench.force.x = -10.0
            assert rospy.ServiceProxy("/mujoco_driver/push", PushEEF)(push).success
            wait_until(lambda: before[0] - tip()[0] > 0.01, 10, "the tool to follow the push along -X")
            moved = tip() - before
            assert rospy.ServiceProxy("/contact_control_node/stop", Trigger)().success
            settle()
            assert np.all(np.abs(moved[1:]) < 0.25 * abs(moved[0])), f"the follower left the X axis: {moved}"
            print(f"\n{robot}: jogged 2 cm along -X; the follower gave way to a 10 N push along -X")
        h.stop()
        assert h.proc.returncode == 0, h.output()[-3000:]
        assert "escalating" not in h.output(), "a node needed SIGTERM/SIGKILL to stop"
    wait_until(lambda: not _registered_nodes().intersection(NODES), 10, "the stack's nodes to unregister")


def _tilt(pose: PoseStamped) -> float:
    """Angle [rad] between the tool tip's z axis and the base z axis."""
    q = pose.pose.orientation
    return float(np.arccos(np.clip(1.0 - 2.0 * (q.x * q.x + q.y * q.y), -1.0, 1.0)))


@pytest.mark.parametrize("robot", ["ur5_custom", "panda_custom"])
def test_reoriented_tool_stays_put_under_a_follower(ros_node, robot):
    """The driver's wrench carries the tool's weight, tared away at the start pose. Tilted by half a radian,
    the weight pulls along other sensor axes (several newtons); contact_control compensates it, so a follower
    (thesis b = 30 N s/m) on X, Y and Z leaves the arm where it is instead of chasing the weight."""
    rospy = ros_node
    with run_launch(robot, "sim.launch") as h:
        for topic in ("/mujoco_driver/eef_pose", "/wrench"):
            h.wait_for_topic(topic, timeout=40)
        h.wait_for_service("/configure_cartesian_impedance", timeout=40)
        clients = _clients(rospy, "/mujoco_driver/eef_pose", "/wrench", "/contact_control_node/status")
        with clients as (pose, wrench, cc_status, twist_pub):
            def force(msg: WrenchStamped) -> np.ndarray:
                f = msg.wrench.force
                return np.array([f.x, f.y, f.z])

            def tip() -> np.ndarray:
                p = pose.last().pose.position
                return np.array([p.x, p.y, p.z])

            before = force(wrench.last())
            tilt0 = _tilt(pose.last())
            # Tilt the tool about the base X axis through jog_arm's input (the keyboard's path).
            twist = TwistStamped()
            twist.header.frame_id = BASE_FRAME[robot]
            twist.twist.angular.x = 0.4
            rate = rospy.Rate(50)
            deadline = rospy.get_time() + 20.0
            while abs(_tilt(pose.last()) - tilt0) < 0.5:
                assert rospy.get_time() < deadline, "the tool did not tilt by 0.5 rad"
                twist.header.stamp = rospy.Time.now()
                twist_pub.publish(twist)
                rate.sleep()  # the sender's rate, not a wait for a result
            wait_until(lambda: max(abs(v) for v in rospy.wait_for_message(
                "/joint_states", JointState, timeout=5).velocity) < 2e-3, 10, "the arm to stop")
            shift = np.linalg.norm(force(wrench.last()) - before)
            assert shift > 3.0, f"tilting moved the weight on the sensor by only {shift:.2f} N"

            req = ConfigureForceControlRequest()
            for axis in ("x", "y", "z"):
                setattr(req.cart_impedance_params.damping.translational, axis, 30.0)
                getattr(req.direction_control_laws, axis).type = ControlLaw.TYPE_FOLLOWER
            assert rospy.ServiceProxy("/configure_cartesian_impedance", ConfigureForceControl)(req).success
            wait_until(lambda: cc_status.last().move_active, 5, "the follower to be active")
            start = tip()
            cc_status.clear()
            cc_status.wait_for(100, timeout=10)  # two seconds of the follower at 50 Hz status
            drift = np.linalg.norm(tip() - start)
            residual = max(np.linalg.norm([m.wrench.force.x, m.wrench.force.y, m.wrench.force.z])
                           for m in cc_status.msgs)
            assert cc_status.last().move_active, cc_status.last().message
            assert drift < 2e-3, f"the follower chased the tool's weight: {drift * 1e3:.1f} mm"
            print(f"\n{robot}: tilted 0.5 rad, the weight moved {shift:.1f} N on the sensor; compensated "
                  f"residual <= {residual:.2f} N; the follower drifted {drift * 1e3:.2f} mm in 2 s")
            assert rospy.ServiceProxy("/contact_control_node/stop", Trigger)().success
