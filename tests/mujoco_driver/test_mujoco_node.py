"""The mujoco_driver node end to end: a private master, the UR5 scene, the topics and services a user sees.

One driver runs for the whole module (namespace /md_test); every test starts from ~reset.
"""

from __future__ import annotations

import itertools
import os
import pathlib
import subprocess
import sys
import time

import numpy as np
import pytest

pytest.importorskip("compliant_control_msgs.srv", reason="needs devel/setup.bash (make test sources it)")

from compliant_control_msgs.srv import PushEEF, PushEEFRequest
from geometry_msgs.msg import PoseStamped, WrenchStamped
from harness.launch import run_node
from harness.waiting import Collector, wait_until
from mujoco_driver.sim import Simulation
from sensor_msgs.msg import JointState
from std_msgs.msg import Float64, Float64MultiArray
from std_srvs.srv import Trigger
from trajectory_msgs.msg import JointTrajectory, JointTrajectoryPoint

from mujoco_driver.config import load_scene_config

ROOT = pathlib.Path(__file__).resolve().parents[2]
CONFIG = ROOT / "src" / "ur5_custom" / "config"
NS = "/md_test"
NODE = f"{NS}/mujoco_driver"
G = 9.81


class Driver:
    """The running driver, collectors on its outputs, and an offline twin of its simulation."""

    def __init__(self, rospy, handle, urdf: str) -> None:
        self.rospy, self.handle = rospy, handle
        self.sim = Simulation(urdf, load_scene_config(str(CONFIG / "sim.yaml")))
        self.names = list(self.sim.joint_names)
        self.start = self.sim.scene.start_pose.copy()
        self.R = self.sim.sensor_rotation()  # sensor axes in the base frame at the start pose
        self.joints = Collector(f"{NS}/joint_states", JointState)
        self.wrench = Collector(f"{NS}/wrench", WrenchStamped)
        self.pose = Collector(f"{NODE}/eef_pose", PoseStamped)
        self.rtf = Collector(f"{NODE}/rtf", Float64)
        self.velocity_pub = rospy.Publisher(f"{NS}/joint_group_velocity_controller/command",
                                            Float64MultiArray, queue_size=1, tcp_nodelay=True)
        self.trajectory_pub = rospy.Publisher(f"{NS}/arm_controller/command", JointTrajectory, queue_size=1,
                                              tcp_nodelay=True)
        self.push_pub = rospy.Publisher(f"{NODE}/push_wrench", WrenchStamped, queue_size=1, tcp_nodelay=True)
        for pub in (self.velocity_pub, self.trajectory_pub, self.push_pub):
            wait_until(lambda pub=pub: pub.get_num_connections() > 0, 10, f"driver subscribed to {pub.name}")
        rospy.wait_for_service(f"{NODE}/reset", 10)
        self.push = rospy.ServiceProxy(f"{NODE}/push", PushEEF)
        self.reset = rospy.ServiceProxy(f"{NODE}/reset", Trigger)

    def q(self) -> np.ndarray:
        return np.array(self.joints.wait_for(1)[-1].position)

    def world_force(self, msg: WrenchStamped) -> np.ndarray:
        f = msg.wrench.force
        return self.R @ [f.x, f.y, f.z]

    def latest_world_force(self) -> np.ndarray:
        return self.world_force(self.wrench.wait_for(1)[-1])

    def fresh_joints(self, count: int = 50) -> list[JointState]:
        """The next ``count`` joint states (published after this call)."""
        self.joints.clear()
        return self.joints.wait_for(count, timeout=10)[:count]

    def publish_while(self, publish, condition, timeout: float, what: str, period: float = 0.02) -> None:
        """Keep publishing (as a controller would) until ``condition`` holds."""
        deadline = time.monotonic() + timeout
        while not condition():
            assert time.monotonic() < deadline, f"timed out after {timeout} s waiting for {what}"
            publish()
            time.sleep(period)  # the sender's rate, not a wait for a result


@pytest.fixture(scope="module")
def driver(ros_node):
    script = ROOT / "src/control_stack/scripts/make_description"
    urdf = subprocess.run(
        [sys.executable, str(script), f"@{CONFIG / 'description.args'}"],
        capture_output=True, text=True, check=True, timeout=60,
    ).stdout
    ros_node.set_param(f"{NS}/robot_description", urdf)
    params = {"scene_config": str(CONFIG / "sim.yaml"), "rtf_period": 1.0}
    with run_node("mujoco_driver", "mujoco_driver", args=[f"__ns:={NS}"], params=params,
                  name="mujoco_driver") as h:
        h.wait_for_topic(f"{NS}/joint_states")
        h.wait_for_topic(f"{NS}/wrench")
        d = Driver(ros_node, h, urdf)
        yield d
        for c in (d.joints, d.wrench, d.pose, d.rtf):
            c.close()


@pytest.fixture
def ur5(driver):
    """The driver back at its start pose, holding still."""
    assert driver.reset().success
    wait_until(lambda: np.allclose(driver.q(), driver.start, atol=1e-3), 5, "the start pose after ~reset")
    driver.joints.clear()
    driver.wrench.clear()
    return driver


def test_joint_states_name_every_joint_and_start_at_the_start_pose(ur5):
    msg = ur5.joints.wait_for(1)[-1]
    assert list(msg.name) == ur5.names
    assert len(msg.position) == len(msg.velocity) == len(msg.effort) == len(ur5.names)
    assert np.allclose(msg.position, ur5.start, atol=1e-3)
    assert np.allclose(msg.velocity, 0.0, atol=1e-3)


def test_joint_states_carry_the_stamp_of_their_wrench_and_follow_it(ur5):
    """joint_states_phase 0.5: the state of each instant goes out after its wrench, with the same stamp."""
    ur5.fresh_joints(5)
    ur5.wrench.clear()
    ur5.fresh_joints(300)
    wrench_times = {m.header.stamp: t for t, m in ur5.wrench.timed()}
    paired = [t - wrench_times[m.header.stamp]
              for t, m in ur5.joints.timed() if m.header.stamp in wrench_times]
    assert len(paired) > 250, "joint states whose stamp no wrench had"
    gap = float(np.median(paired))
    print(f"\njoint_states arrive {gap * 1e3:.2f} ms (median) after the wrench of the same instant")
    assert gap > 0.0


def test_command_latency_pairs_commands_with_the_wrenches_before_them(ur5):
    """~command_latency: per wrench, the wait for the next joint command; nothing while nobody commands."""
    batches = Collector(f"{NODE}/command_latency", Float64MultiArray)
    try:
        batches.wait_connected()
        hold = Float64MultiArray(data=[0.0] * len(ur5.names))
        sent_from = time.time()
        ur5.publish_while(lambda: ur5.velocity_pub.publish(hold), lambda: len(batches.msgs) >= 2, 10,
                          "two batches of latencies", period=0.01)
        samples = np.concatenate([np.reshape(m.data, (-1, 2)) for m in batches.msgs])
        dims = batches.msgs[-1].layout.dim
        assert dims[0].size == len(batches.msgs[-1].data) // 2 and dims[1].size == 2
        wall, latency = samples[:, 0], samples[:, 1]
        assert np.all(wall >= sent_from - 1.0) and np.all(wall <= time.time())
        # A command every 10 ms answers the ~5 wrenches (500 Hz) published since the one before.
        assert np.all(latency >= 0.0) and np.all(latency <= 0.25)
        per_command = len(latency) / len(np.unique(wall))
        assert 2.0 < per_command < 10.0, per_command
        # Commands stopped: after two reports (the first may carry the last commands) nothing more comes.
        ur5.rtf.clear()
        ur5.rtf.wait_for(2, timeout=10)
        batches.clear()
        ur5.rtf.wait_for(4, timeout=10)
        assert not batches.msgs
    finally:
        batches.close()


def test_wrench_at_rest_shows_the_tool_weight_in_the_sensor_frame(ur5):
    msg = ur5.wrench.wait_for(1)[-1]
    assert msg.header.frame_id == "ft_sensor"
    f = msg.wrench.force
    # The tool (1 kg) hangs below the sensor, whose z axis points down: +9.81 N along sensor z.
    assert np.allclose([f.x, f.y, f.z], ur5.R.T @ [0.0, 0.0, -G], atol=0.05)
    assert np.allclose(ur5.latest_world_force(), [0.0, 0.0, -G], atol=0.05)


def test_push_service_shows_the_pushed_force_while_it_lasts(ur5):
    answer = ur5.push(PushEEFRequest(wrench=_wrench(force=(10.0, 0.0, 0.0)), duration=0.5))
    assert answer.success, answer.message
    wait_until(lambda: ur5.latest_world_force()[0] > 9.5, 5, "the 10 N push on the wrench topic")
    assert abs(ur5.latest_world_force()[2] + G) < 0.5  # the weight is still there
    wait_until(lambda: abs(ur5.latest_world_force()[0]) < 0.2, 5, "the push to end")


def test_push_service_refuses_a_negative_duration_and_still_pushes_after(ur5):
    answer = ur5.push(PushEEFRequest(wrench=_wrench(force=(10.0, 0.0, 0.0)), duration=-1.0))
    assert not answer.success and "duration" in answer.message
    assert all(abs(ur5.world_force(m)[0]) < 0.2 for m in ur5.wrench.wait_for(50))
    assert ur5.push(PushEEFRequest(wrench=_wrench(force=(0.0, 8.0, 0.0)), duration=0.3)).success
    wait_until(lambda: ur5.latest_world_force()[1] > 7.5, 5, "the valid push after a refused one")


def test_push_wrench_topic_pushes_while_messages_keep_coming(ur5):
    push = WrenchStamped()
    push.wrench.force.z = 15.0  # lift the tool: the sensor then reads 15 - 9.81 N up
    ur5.publish_while(lambda: ur5.push_pub.publish(push),
                      lambda: ur5.latest_world_force()[2] > 15.0 - G - 0.3, 5, "the topic push on the wrench")
    # No more messages: the push ends push_timeout (0.2 s) later.
    wait_until(lambda: abs(ur5.latest_world_force()[2] + G) < 0.2, 5, "the topic push to end")


def test_velocity_on_one_joint_moves_that_joint_and_stops_when_commands_stop(ur5):
    joint = ur5.names.index("wrist_3_joint")
    velocity = [0.0] * len(ur5.names)
    velocity[joint] = 0.5
    cmd = Float64MultiArray(data=velocity)
    start = ur5.q()
    ur5.publish_while(lambda: ur5.velocity_pub.publish(cmd), lambda: ur5.q()[joint] - start[joint] > 0.2,
                      10, "wrist_3 to turn by 0.2 rad")
    moved = ur5.q() - start
    assert np.all(np.abs(np.delete(moved, joint)) < 0.01), f"other joints moved: {moved}"
    # Commands stop: the watchdog (command_timeout 0.1 s) brings the velocity to zero.
    wait_until(lambda: abs(ur5.joints.wait_for(1)[-1].velocity[joint]) < 1e-3, 5, "the joint to stop")
    held = [m.position[joint] for m in ur5.fresh_joints(100)]
    assert max(held) - min(held) < 1e-3


def test_trajectory_moves_the_joints_to_the_target(ur5):
    target = ur5.start + np.array([0.1, -0.1, 0.1, 0.1, -0.1, 0.2])
    msg = JointTrajectory(joint_names=ur5.names[::-1])  # any name order
    msg.points = [JointTrajectoryPoint(positions=target[::-1].tolist(), time_from_start=_seconds(1.0))]
    ur5.trajectory_pub.publish(msg)

    def arrived() -> bool:
        last = ur5.joints.wait_for(1)[-1]
        return np.allclose(last.position, target, atol=1e-3) and np.allclose(last.velocity, 0.0, atol=1e-3)

    wait_until(arrived, 10, "the trajectory's target, at rest")
    held = np.array([m.position for m in ur5.fresh_joints(50)])
    assert np.allclose(held, target, atol=1e-3)
    # Stamped 10 s ago (a sender on another clock): started now, with a warning, and still executed.
    msg.header.stamp = ur5.rospy.Time.now() - ur5.rospy.Duration(10.0)
    msg.points[0].positions = ur5.start[::-1].tolist()
    ur5.trajectory_pub.publish(msg)
    target = ur5.start
    wait_until(arrived, 10, "the start pose again, after an old-stamped trajectory")
    assert "clocks differ?" in ur5.handle.output()


def test_bad_commands_are_ignored_and_the_arm_holds(ur5):
    n = len(ur5.names)
    nan = Float64MultiArray(data=[float("nan")] + [0.3] * (n - 1))
    short = Float64MultiArray(data=[0.3] * (n - 1))
    unknown = JointTrajectory(joint_names=["no_such_joint", *ur5.names[1:]])
    unknown.points = [JointTrajectoryPoint(positions=(ur5.start + 0.2).tolist(),
                                           time_from_start=_seconds(0.5))]
    nan_traj = JointTrajectory(joint_names=ur5.names)
    nan_traj.points = [JointTrajectoryPoint(positions=[float("nan")] * n, time_from_start=_seconds(0.5))]
    for _ in range(5):
        for msg in (nan, short):
            ur5.velocity_pub.publish(msg)
        for msg in (unknown, nan_traj):
            ur5.trajectory_pub.publish(msg)
        held = np.array([m.position for m in ur5.fresh_joints(20)])
        assert np.allclose(held, ur5.start, atol=1e-3)
    for what in ("velocity command ignored", "trajectory ignored"):
        wait_until(lambda what=what: what in ur5.handle.output(), 5, f"a warning: {what}")
    # The driver still takes a valid command afterwards.
    target = ur5.start.copy()
    target[0] += 0.05
    good = JointTrajectory(joint_names=ur5.names)
    good.points = [JointTrajectoryPoint(positions=target.tolist(), time_from_start=_seconds(0.3))]
    ur5.trajectory_pub.publish(good)
    wait_until(lambda: np.allclose(ur5.q(), target, atol=2e-3), 5, "the valid trajectory after bad ones")


def test_reset_returns_to_the_start_pose(ur5):
    cmd = Float64MultiArray(data=[0.3] * len(ur5.names))
    ur5.publish_while(lambda: ur5.velocity_pub.publish(cmd),
                      lambda: np.max(np.abs(ur5.q() - ur5.start)) > 0.1, 10, "the arm to move away")
    assert ur5.reset().success
    wait_until(lambda: np.allclose(ur5.q(), ur5.start, atol=1e-4), 5, "the start pose")
    assert np.allclose(ur5.fresh_joints(1)[0].velocity, 0.0, atol=1e-3)


def test_eef_pose_is_the_tool_tip_in_the_base_frame(ur5):
    # At the start pose, as the local model: other tests (in any order) leave the arm elsewhere.
    assert ur5.reset().success
    wait_until(lambda: np.allclose(ur5.q(), ur5.start, atol=1e-6), 5, "the start pose")
    ur5.pose.clear()
    msg = ur5.pose.wait_for(1)[-1]  # published after the reset
    position, quat = ur5.sim.eef_pose()
    p, o = msg.pose.position, msg.pose.orientation
    assert msg.header.frame_id == "world"  # the UR5 URDF's root link
    assert np.allclose([p.x, p.y, p.z], position, atol=1e-4)
    assert abs(np.dot([o.x, o.y, o.z, o.w], quat)) > 1 - 1e-6


def test_real_time_factor_and_cpu_are_printed(ur5, capsys):
    """Benchmark (no timing assertion): the driver's real-time factor on ~rtf and its CPU use."""
    pid = _driver_pid(ur5.handle.proc.pid)
    ur5.rtf.clear()
    cpu0, wall0 = _cpu_seconds(pid), time.monotonic()
    samples = ur5.rtf.wait_for(3, timeout=10)
    cpu = (_cpu_seconds(pid) - cpu0) / (time.monotonic() - wall0)
    stamps = [m.header.stamp.to_sec() for m in ur5.fresh_joints(500)]
    rate = (len(stamps) - 1) / (stamps[-1] - stamps[0])
    with capsys.disabled():
        print(f"\nmujoco_driver (UR5, 500 Hz publishing): real-time factor "
              f"{', '.join(f'{m.data:.3f}' for m in samples)}; joint_states at {rate:.0f} Hz; "
              f"CPU {100 * cpu:.0f} % of one core")
    assert all(m.data > 0.0 for m in samples)


def test_a_display_that_refuses_leaves_the_driver_running_headless_and_saying_why(driver, ros_node):
    """~viewer with a DISPLAY nobody serves: MuJoCo's viewer would end the process; the driver goes on."""
    ns = "/md_refused"
    ros_node.set_param(f"{ns}/robot_description", ros_node.get_param(f"{NS}/robot_description"))
    params = {"scene_config": str(CONFIG / "sim.yaml"), "viewer": True}
    env = {**{k: v for k, v in os.environ.items() if k != "WAYLAND_DISPLAY"}, "DISPLAY": ":65000"}
    joints = Collector(f"{ns}/joint_states", JointState)
    try:
        with run_node("mujoco_driver", "mujoco_driver", args=[f"__ns:={ns}"], params=params,
                      name="mujoco_driver", env=env) as h:
            wait_until(lambda: "running headless" in h.output(), 30, "the headless warning")
            assert "Failed to open display :65000" in h.output(), h.output()[-2000:]
            joints.clear()
            joints.wait_for(20)  # still simulating after the refusal
            assert h.proc.poll() is None, h.output()[-2000:]
    finally:
        joints.close()


def test_sim_time_mode_publishes_a_clock_that_stamps_the_state_and_survives_reset(driver, ros_node):
    """~publish_clock with real_time_factor 0: /clock advances as fast as the machine allows, the joint states
    carry simulated time, and ~reset does not turn the clock back. ~viewer without a DISPLAY: headless."""
    from rosgraph_msgs.msg import Clock

    ns = "/md_clock"
    ros_node.set_param(f"{ns}/robot_description", ros_node.get_param(f"{NS}/robot_description"))
    params = {"scene_config": str(CONFIG / "sim.yaml"), "publish_clock": True, "real_time_factor": 0,
              "publish_period": 0.01, "viewer": True}
    env = {k: v for k, v in os.environ.items() if k not in ("DISPLAY", "WAYLAND_DISPLAY")}
    clock = Collector("/clock", Clock)
    joints = Collector(f"{ns}/joint_states", JointState)
    try:
        with run_node("mujoco_driver", "mujoco_driver", args=[f"__ns:={ns}"], params=params,
                      name="mujoco_driver", env=env) as h:
            h.wait_for_topic("/clock")
            wait_until(lambda: "no DISPLAY: running headless" in h.output(), 10, "the headless warning")
            wall0 = time.monotonic()
            ticks = clock.wait_for(500, timeout=20)
            first = joints.wait_for(5)[-1].header.stamp.to_sec()
            sim_seconds = ticks[-1].clock.to_sec() - ticks[0].clock.to_sec()
            ros_node.wait_for_service(f"{ns}/mujoco_driver/reset", 10)
            before = clock.last().clock.to_sec()
            assert ros_node.ServiceProxy(f"{ns}/mujoco_driver/reset", Trigger)().success
            clock.clear()
            after = [m.clock.to_sec() for m in clock.wait_for(50)]
            speed = sim_seconds / (time.monotonic() - wall0)
    finally:
        clock.close()
        joints.close()
    assert 0.0 < first < 1000.0  # simulated seconds since start, not the wall clock's ~1.7e9
    assert min(after) >= before and all(b > a for a, b in itertools.pairwise(after))
    print(f"\nmujoco_driver with real_time_factor 0 (clock at every step): ~{speed:.1f} x real time")


def _wrench(force=(0.0, 0.0, 0.0), torque=(0.0, 0.0, 0.0)):
    from geometry_msgs.msg import Wrench

    msg = Wrench()
    msg.force.x, msg.force.y, msg.force.z = force
    msg.torque.x, msg.torque.y, msg.torque.z = torque
    return msg


def _seconds(value: float):
    import rospy

    return rospy.Duration.from_sec(value)


def _driver_pid(rosrun_pid: int) -> int:
    """rosrun execs or forks the node: the python process under it."""
    children = pathlib.Path(f"/proc/{rosrun_pid}/task/{rosrun_pid}/children").read_text().split()
    return int(children[0]) if children else rosrun_pid


def _cpu_seconds(pid: int) -> float:
    fields = pathlib.Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")


