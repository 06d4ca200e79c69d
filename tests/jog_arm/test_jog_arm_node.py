"""jog_arm_server end to end: a private master, replayed joint states, twists in, joint commands out."""

from __future__ import annotations

import contextlib
import itertools
import math
import threading
import time
from collections.abc import Iterator

import numpy as np
import pinocchio as pin
import pytest
from harness.bags import replay_bag, typestore, write_bag
from harness.launch import run_launch, run_node
from harness.streams import Repeater
from harness.waiting import Collector, wait_until
from jog_arm_testing import PANDA, SO100, UR5, Robot, angle_deg, ur5_launch_override

from jog_arm import ArmModel, StatusCode

JogStatus = pytest.importorskip("compliant_control_msgs.msg", reason="build the workspace first").JogStatus

FINGERS = ("panda_finger_joint1", "panda_finger_joint2")


def panda_joint_bag(path, seconds: float, rate: float = 100.0) -> None:
    """A bag of a Panda standing still at the start pose, fingers included (as franka_ros publishes)."""
    ts = typestore()
    JointState = ts.types["sensor_msgs/msg/JointState"]
    Header = ts.types["std_msgs/msg/Header"]
    Time = ts.types["builtin_interfaces/msg/Time"]
    names = [f"panda_joint{i}" for i in range(1, 8)] + list(FINGERS)
    position = np.array([*PANDA.start, 0.02, 0.02])
    entries = []
    for k in range(int(seconds * rate)):
        stamp = 1_000_000_000 + int(k * 1e9 / rate)
        header = Header(seq=k, stamp=Time(sec=stamp // 10**9, nanosec=stamp % 10**9), frame_id="")
        msg = JointState(
            header=header, name=names, position=position, velocity=np.zeros(9), effort=np.zeros(9)
        )
        entries.append(("/jog_test/joint_states", "sensor_msgs/msg/JointState", stamp, msg))
    write_bag(path, entries)


def set_params(rospy, node: str, params: dict) -> None:
    """Private parameters set on the master before the node starts (nested values included)."""
    for key, value in params.items():
        rospy.set_param(f"/{node}/{key}", value)


def twist_msg(values: tuple[float, ...], frame: str = ""):
    from geometry_msgs.msg import TwistStamped

    msg = TwistStamped()
    msg.header.frame_id = frame
    (msg.twist.linear.x, msg.twist.linear.y, msg.twist.linear.z) = values[:3]
    (msg.twist.angular.x, msg.twist.angular.y, msg.twist.angular.z) = values[3:]
    return msg


def panda_params(**extra) -> dict:
    return {
        "ee_frame_name": PANDA.tip,
        "planning_frame": PANDA.planning_frame,
        "command_in_type": "speed_units",
        "pub_period": 0.01,
        "incoming_cmd_timeout": 0.3,
        "integrate_from": "measured",  # every output starts from the replayed state
        "joint_topic": "/jog_test/joint_states",
        "cmd_in_topic": "/jog_test/twist",
        "cmd_out_topic": "/jog_test/command",
        "num_outgoing_halt_msgs_to_publish": 5,
        **PANDA.params,
        **extra,
    }


class Sender(Repeater):
    """Publishes a twist at a steady rate from a thread until stopped (a teleop device)."""

    def __init__(self, rospy, topic: str) -> None:
        from geometry_msgs.msg import TwistStamped

        super().__init__(rospy.Publisher(topic, TwistStamped, queue_size=1, tcp_nodelay=True))


@contextlib.contextmanager
def node_log_on_failure(node) -> Iterator[None]:
    """Adds the node's output to a failing assertion (the node runs in another process)."""
    try:
        yield
    except AssertionError as err:
        raise AssertionError(f"{err}\n--- node output ---\n{node.output()[-4000:]}") from err


def eef_velocity(model: ArmModel, q, dq) -> np.ndarray:
    return model.jacobian(np.asarray(q, dtype=float)) @ np.asarray(dq, dtype=float)


def test_replayed_state_twist_in_trajectory_out_then_stale_stop_and_refusals(ros_node, tmp_path) -> None:
    from trajectory_msgs.msg import JointTrajectory

    rospy = ros_node
    bag = tmp_path / "panda_joint_states.bag"
    panda_joint_bag(bag, seconds=12.0)
    rospy.set_param("/robot_description", PANDA.urdf)
    name = "jog_test_panda"
    set_params(rospy, name, panda_params())
    model = ArmModel(PANDA.urdf, PANDA.tip)

    commands = Collector("/jog_test/command", JointTrajectory)
    status = Collector(f"/{name}/status", JogStatus)
    sender = Sender(rospy, "/jog_test/twist")
    with run_node("jog_arm", "jog_arm_server", name=name) as node, node_log_on_failure(node):
        node.wait_for_topic("/jog_test/command")
        replay = threading.Thread(target=replay_bag, args=(bag,), daemon=True)
        replay.start()
        try:
            wait_until(
                lambda: status.msgs and status.msgs[-1].code == StatusCode.STALE_COMMAND, 20, "joint state"
            )
            assert not commands.msgs  # nothing is sent before the first command
            wait_until(
                lambda: sender.pub.get_num_connections() > 0, 10, "jog_arm_server subscribed to twists"
            )

            # A +x twist in the planning frame: the EEF velocity of each command points along +x.
            sender.start(twist_msg((0.05, 0.0, 0.0, 0.0, 0.0, 0.0)))
            commands.wait_for(30, timeout=10)
            msg = commands.last()
            assert list(msg.joint_names) == [f"panda_joint{i}" for i in range(1, 8)]
            assert len(msg.points) == 1
            point = msg.points[0]
            assert point.time_from_start.to_sec() == pytest.approx(0.01)
            twist = eef_velocity(model, PANDA.start, point.velocities)
            assert angle_deg(twist[:3], np.array([1.0, 0.0, 0.0])) < 1.0
            assert np.linalg.norm(twist[:3]) == pytest.approx(0.05, rel=0.02)  # filter settled, DC gain 1
            assert np.linalg.norm(twist[3:]) < 1e-3
            expected = (
                np.array(PANDA.start) + np.array(point.velocities) * 0.01
            )  # publish period, not CPU time
            np.testing.assert_allclose(point.positions, expected, atol=1e-9)
            moving = status.last()  # the collaborative speed cap (default: the hand), far above 0.05 m/s
            assert moving.body_region == "hand" and 1.0 < moving.speed_cap < 2.0, moving

            # The sender stops: smooth stop, the zero command 5 times, then silence. The node's publisher
            # keeps only the newest message (queue_size 1, as a controller wants), so on a busy machine a
            # few may never reach us: count at most 5 zeros, at least one, and nothing after them.
            sender.stop()
            wait_until(lambda: not any(commands.last().points[0].velocities), 10, "a zero command")
            seen = len(status.msgs)
            wait_until(lambda: len(status.msgs) > seen + 30, 10, "30 more cycles")  # 0.3 s of node cycles
            speeds = [float(np.linalg.norm(m.points[0].velocities)) for m in commands.msgs]
            stop_at = speeds.index(0.0)
            assert 1 <= len(speeds) - stop_at <= 5 and not any(speeds[stop_at:])
            tail = speeds[stop_at - 3 : stop_at + 1]
            assert all(a >= b for a, b in itertools.pairwise(tail)) and tail[0] > 0.0
            assert any(m.code == StatusCode.STALE_COMMAND for m in status.msgs[seen:])

            # NaN: refused with a reason, the arm holds still (no command at all).
            commands.clear()
            sender.pub.publish(twist_msg((math.nan, 0.0, 0.0, 0.0, 0.0, 0.0)))
            wait_until(lambda: status.last().code == StatusCode.INVALID_COMMAND, 10, "INVALID_COMMAND")
            assert "non-finite" in status.last().message
            assert status.last().code_name == "INVALID_COMMAND"  # rostopic echo reads the code in words
            seen = len(status.msgs)
            wait_until(lambda: len(status.msgs) > seen + 20, 10, "20 more cycles")
            assert not commands.msgs

            # A frame neither the URDF nor tf knows: refused too.
            sender.pub.publish(twist_msg((0.05, 0.0, 0.0, 0.0, 0.0, 0.0), frame="nowhere"))
            wait_until(lambda: "unknown frame" in status.last().message, 10, "unknown frame refusal")
            assert not commands.msgs

            # Still works afterwards: a -z twist in the hand frame.
            sender.start(twist_msg((0.0, 0.0, -0.05, 0.0, 0.0, 0.0), frame=PANDA.tip))
            commands.wait_for(20, timeout=10)
            hand_z = model.frame_pose(np.array(PANDA.start), PANDA.tip).rotation[:, 2]
            twist = eef_velocity(model, PANDA.start, commands.last().points[0].velocities)
            assert angle_deg(twist[:3], -hand_z) < 1.0
            sender.stop()
        finally:
            sender.stop()
            commands.close()
            status.close()
        assert "refused" in node.output()  # the refusals were logged


def test_velocity_output_tf_frame_pause_and_launch_file(ros_node, tmp_path) -> None:
    """UR5 through the launch file with an override YAML: Float64MultiArray out, a tf-only command frame."""
    import rospy as _rospy  # noqa: F401 (ros_node initialised it)
    import tf2_ros
    from geometry_msgs.msg import TransformStamped
    from sensor_msgs.msg import JointState
    from std_msgs.msg import Float64MultiArray
    from std_srvs.srv import Trigger

    rospy = ros_node
    rospy.set_param("/robot_description", UR5.urdf)
    override = ur5_launch_override(tmp_path, "/jog_ur5")
    # A camera frame only tf knows: x along the base's y.
    broadcaster = tf2_ros.StaticTransformBroadcaster()
    tf = TransformStamped()
    tf.header.stamp = rospy.Time.now()
    tf.header.frame_id, tf.child_frame_id = "base_link", "camera"
    tf.transform.rotation.z, tf.transform.rotation.w = math.sin(math.pi / 4), math.cos(math.pi / 4)
    broadcaster.sendTransform(tf)

    model = ArmModel(UR5.urdf, UR5.tip)
    joints = rospy.Publisher("/jog_ur5/joint_states", JointState, queue_size=1, latch=True)
    state = JointState(name=list(model.joint_names), position=list(UR5.start))
    driver = Repeater(joints).start(state, rate=100.0)  # a driver streams its state (joint_state_timeout)
    speeds = Collector("/jog_ur5/speed", Float64MultiArray)
    name = "jog_test_ur5"
    status = Collector(f"/{name}/status", JogStatus)
    sender = Sender(rospy, "/jog_ur5/twist")
    args = {"node_name": name, "override_config": str(override)}
    with run_launch("jog_arm", "jog_arm.launch", args=args) as launched, node_log_on_failure(launched):
        launched.wait_for_topic("/jog_ur5/speed")
        try:
            wait_until(lambda: sender.pub.get_num_connections() > 0, 20, "jog_arm_server subscribed")
            wait_until(lambda: status.msgs and status.msgs[-1].code == StatusCode.STALE_COMMAND, 20, "state")
            sender.start(twist_msg((0.5, 0.0, 0.0, 0.0, 0.0, 0.0), frame="camera"), rate=100.0)
            speeds.wait_for(100, timeout=10)
            velocities = speeds.last().data
            assert len(velocities) == 6
            twist = eef_velocity(model, UR5.start, velocities)
            assert angle_deg(twist[:3], np.array([0.0, 1.0, 0.0])) < 1.0  # camera x = base y
            assert np.linalg.norm(twist[:3]) == pytest.approx(0.05, rel=0.05)  # 0.5 x scale/linear

            pause = rospy.ServiceProxy(f"/{name}/pause", Trigger)
            answer = pause()  # answers once stopped and silent: whoever paused it may use the driver now
            assert answer.success and answer.message.startswith("paused: at rest after stopping"), answer
            time.sleep(0.05)  # the last commands still on the wire
            published = len(speeds.msgs)
            assert not any(speeds.last().data)
            time.sleep(0.3)  # twists keep coming at 100 Hz: ignored, nothing published
            assert len(speeds.msgs) == published
            assert status.last().code == StatusCode.PAUSED
            assert pause().message.startswith("already paused")
            assert rospy.ServiceProxy(f"/{name}/resume", Trigger)().success
            wait_until(lambda: any(speeds.last().data), 10, "moving again after resume")
        finally:
            sender.stop()
            speeds.close()
            status.close()
            driver.stop()
            joints.unregister()


def test_invalid_configuration_refuses_to_start(ros_node) -> None:
    rospy = ros_node
    rospy.set_param("/robot_description", UR5.urdf)
    name = "jog_test_refused"
    set_params(rospy, name, {"singularity_threshold": 12.0, "hard_stop_singularity_threshold": 7.0})
    with run_node("jog_arm", "jog_arm_server", name=name) as node:
        wait_until(lambda: node.proc.poll() is not None, 30, "jog_arm_server to exit")
        assert node.proc.returncode != 0
        assert f"/{name}/hard_stop_singularity_threshold" in node.output()


@contextlib.contextmanager
def arm_server(rospy, name: str, prefix: str, params: dict, out_class: type, robot: Robot = UR5):
    """jog_arm_server for `robot` at its start pose on `prefix` topics: yields (commands, twist sender)."""
    from sensor_msgs.msg import JointState

    rospy.set_param("/robot_description", robot.urdf)
    topics = {
        "joint_topic": f"{prefix}/joint_states",
        "cmd_in_topic": f"{prefix}/twist",
        "cmd_out_topic": f"{prefix}/command",
    }
    set_params(rospy, name, {"command_in_type": "speed_units", **topics, **params})
    joints = rospy.Publisher(topics["joint_topic"], JointState, queue_size=1, latch=True)
    state = JointState(name=list(ArmModel(robot.urdf, robot.tip).joint_names), position=list(robot.start))
    driver = Repeater(joints).start(state, rate=100.0)  # a driver streams its state (joint_state_timeout)
    commands = Collector(topics["cmd_out_topic"], out_class)
    sender = Sender(rospy, topics["cmd_in_topic"])
    with run_node("jog_arm", "jog_arm_server", name=name) as node, node_log_on_failure(node):
        node.wait_for_topic(topics["cmd_out_topic"])
        try:
            wait_until(lambda: sender.pub.get_num_connections() > 0, 20, "jog_arm_server subscribed")
            yield commands, sender
        finally:
            sender.stop()
            commands.close()
            driver.stop()
            joints.unregister()


def test_simu_mode_sends_several_points(ros_node) -> None:
    from trajectory_msgs.msg import JointTrajectory

    params = {"simu": True, "simu_points": 3, "pub_period": 0.005}
    with arm_server(ros_node, "jog_test_simu", "/jog_simu", params, JointTrajectory) as (commands, sender):
        sender.start(twist_msg((0.0, 0.0, 0.05, 0.0, 0.0, 0.0)))
        msg = commands.wait_for(10, timeout=10)[-1]
        times = [p.time_from_start.to_sec() for p in msg.points]
        assert times == pytest.approx([0.005, 0.010, 0.015])
        q = [np.array(p.positions) for p in msg.points]
        v = np.array(msg.points[0].velocities)
        np.testing.assert_allclose(q[2] - q[1], v * 0.005, atol=1e-12)  # extrapolated at the velocity


def test_pinocchio_frame_pose_matches_tf_convention() -> None:
    """The quaternion conversion the node uses for tf frames (x, y, z, w) gives the rotation tf means."""
    quat = pin.Quaternion(math.cos(math.pi / 4), 0.0, 0.0, math.sin(math.pi / 4))  # w, x, y, z
    np.testing.assert_allclose(quat.toRotationMatrix() @ [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], atol=1e-12)


def test_publish_on_command_answers_every_twist_without_waiting_for_the_timer(ros_node) -> None:
    from std_msgs.msg import Float64MultiArray

    params = {
        "publish_on_command": True,
        "pub_period": 2.0,  # the timer alone would give one command per 2 s
        "command_out_type": "velocity_array",
        "integrate_from": "measured",
    }
    with arm_server(ros_node, "jog_test_on_command", "/jog_oncmd", params, Float64MultiArray) as (
        commands,
        sender,
    ):
        commands.wait_connected()
        commands.clear()
        sender.start(twist_msg((0.0, 0.0, 0.05, 0.0, 0.0, 0.0)), rate=50.0)
        commands.wait_for(20, timeout=5)  # ~50 per second, where the 2 s timer alone gives 2 or 3
        v = eef_velocity(ArmModel(UR5.urdf, UR5.tip), UR5.start, commands.last().data)
        assert v[2] > 0.0 and abs(v[0]) < 0.2 * v[2] and abs(v[1]) < 0.2 * v[2]


def test_contact_controls_twists_pass_the_guard_and_others_do_not(ros_node) -> None:
    """Two-node layout: contact_control's twists reach jog_arm on an input of their own
    (contact_cmd_in_topic). At 25 N (over the 20 N guard limit) a twist into the contact on cmd_in_topic (a
    keyboard's) becomes a retreat, the same twist on contact_cmd_in_topic passes: contact_control's laws react
    to the force themselves (a compliant move's move_away, a force-tracking press). Both come from this one
    node: nothing depends on who sends. (The collaborative region is off: with it, the held push would be a
    clamp, backed off at clamp_release_speed: test_jog_arm_clamp.)"""
    from geometry_msgs.msg import WrenchStamped
    from std_msgs.msg import Float64MultiArray

    rospy = ros_node
    params = {
        "command_out_type": "velocity_array", "integrate_from": "measured",
        "contact_guard_wrench_topic": "/jog_guard/contact",
        "contact_cmd_in_topic": "/jog_guard/contact_twist", "collaborative_region": "off",
    }
    contact = rospy.Publisher("/jog_guard/contact", WrenchStamped, queue_size=1)
    press = WrenchStamped()
    press.header.frame_id = UR5.planning_frame
    press.wrench.force.z = 25.0  # the surface pushes the tool up
    pressing = Repeater(contact).start(press, rate=100.0)
    model = ArmModel(UR5.urdf, UR5.tip)
    laws = Sender(rospy, "/jog_guard/contact_twist")

    def vz() -> float:
        return float(eef_velocity(model, UR5.start, commands.last().data)[2])

    try:
        with arm_server(rospy, "jog_test_guard", "/jog_guard", params, Float64MultiArray) as (
            commands,
            sender,
        ):
            commands.wait_connected()
            wait_until(lambda: laws.pub.get_num_connections() > 0, 20, "jog_arm on contact_cmd_in_topic")
            # contact_control's input: down into the contact as asked.
            laws.start(twist_msg((0.0, 0.0, -0.02, 0.0, 0.0, 0.0)), rate=50.0)
            commands.wait_for(10, timeout=5)
            wait_until(lambda: vz() < -0.015, 5, "the contact_cmd_in_topic twist to move down")
            laws.stop()
            # The outside input: the same twist is guarded into a retreat.
            sender.start(twist_msg((0.0, 0.0, -0.02, 0.0, 0.0, 0.0)), rate=50.0)
            wait_until(lambda: 0.0 < vz() <= 0.0051, 10, "the guarded twist to back off at 5 mm/s")
            sender.stop()
    finally:
        laws.stop()
        laws.pub.unregister()
        pressing.stop()
        contact.unregister()


def test_a_five_joint_arm_jogs_and_its_status_names_the_rotation_it_cannot_make(ros_node) -> None:
    """The SO-100 (5 joints): a twist along X moves the tip along X, and the status carries the rotation
    axis it cannot make (a unit vector of planning_frame) and says so."""
    from compliant_control_msgs.msg import JogStatus
    from std_msgs.msg import Float64MultiArray

    params = {"ee_frame_name": SO100.tip, "planning_frame": SO100.planning_frame, "cmd_frame": "",
              "command_out_type": "velocity_array", "integrate_from": "measured", **SO100.params}
    status = Collector("/jog_so100/status", JogStatus)
    try:
        with arm_server(ros_node, "jog_so100", "/jog_five", params, Float64MultiArray, SO100) as (commands,
                                                                                                sender):
            sender.start(twist_msg((0.02, 0.0, 0.0, 0.0, 0.0, 0.0)))
            commands.wait_for(20, timeout=10)
            v = eef_velocity(ArmModel(SO100.urdf, SO100.tip), SO100.start, commands.last().data)
            assert v[0] > 0.0 and abs(v[1]) < 0.05 * v[0] and abs(v[2]) < 0.05 * v[0]
            wait_until(lambda: any(m.uncontrolled_rotations for m in list(status.msgs)), 10,
                       "a status naming the uncontrolled rotation")
            last = next(m for m in reversed(list(status.msgs)) if m.uncontrolled_rotations)
            (axis,) = last.uncontrolled_rotations
            assert math.isclose(math.hypot(axis.x, axis.y, axis.z), 1.0, rel_tol=1e-6)
            assert "cannot turn about [" in last.message and "of base" in last.message, last.message
    finally:
        status.close()
