"""End to end, the faults of a real cell on the simulated robots: the command source vanishes mid-jog (killed
like Ctrl-C, or hung), the driver dies mid-jog, roscore restarts under a running stack. Each must stop the
arm, say why, and (for the master) come back without a human."""

from __future__ import annotations

import contextlib
import os
import signal
import subprocess
import time

import numpy as np
import pytest

pytest.importorskip("cartesian_impedance_msgs.srv", reason="needs devel/setup.bash (make test sources it)")

from cartesian_impedance_msgs.msg import ControlLaw
from cartesian_impedance_msgs.srv import ConfigureForceControl, ConfigureForceControlRequest
from compliant_common.ros_master import MasterWatch
from compliant_control_msgs.msg import ContactControlStatus, JogStatus
from compliant_control_msgs.srv import PushEEF, PushEEFRequest
from geometry_msgs.msg import PoseStamped
from harness.launch import run_launch
from harness.process import node_pid
from harness.ros_env import start_master
from harness.waiting import Collector, wait_until
from sensor_msgs.msg import JointState
from std_msgs.msg import Float64MultiArray

BASE_FRAME = {"ur5_custom": "base_link", "panda_custom": "panda_link0"}
SPEED = 0.05  # [m/s] the README's jog command


def _tip(pose: Collector) -> np.ndarray:
    p = pose.last().pose.position
    return np.array([p.x, p.y, p.z])


def _tip_at(pose: Collector, when: float) -> np.ndarray:
    """The tool tip's position received last before `when` (monotonic)."""
    before = [m for t, m in pose.timed() if t <= when]
    p = before[-1].pose.position
    return np.array([p.x, p.y, p.z])


def _speed_x(first: PoseStamped, last: PoseStamped) -> float:
    """The tool tip's speed along -X between two of the driver's poses, by their stamps (simulated time)."""
    dt = (last.header.stamp - first.header.stamp).to_sec()
    return (first.pose.position.x - last.pose.position.x) / dt


@contextlib.contextmanager
def _readme_jog(robot: str):
    """The robot README's `rostopic pub -r 50` jog command (5 cm/s along -X), as its own process."""
    body = f"{{header: {{frame_id: {BASE_FRAME[robot]}}}, twist: {{linear: {{x: -{SPEED}}}}}}}"
    proc = subprocess.Popen(
        ["rostopic", "pub", "-r", "50", "/jog_arm_server/delta_jog_cmds", "geometry_msgs/TwistStamped", body],
        stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, start_new_session=True,
    )
    try:
        yield proc
    finally:
        with contextlib.suppress(ProcessLookupError):
            os.killpg(proc.pid, signal.SIGCONT)
            os.killpg(proc.pid, signal.SIGKILL)
        proc.wait()


def _stack(h) -> None:
    for topic in ("/mujoco_driver/eef_pose", "/joint_states", "/jog_arm_server/status"):
        h.wait_for_topic(topic, timeout=40)
    h.wait_for_service("/configure_cartesian_impedance", timeout=40)


def _wait_for_travel(pose: Collector, distance: float) -> None:
    """Waits until the tool tip has moved `distance` along -X from where it is now."""
    x0 = _tip(pose)[0]
    wait_until(lambda: x0 - _tip(pose)[0] > distance, 30, f"the tool to move {distance} m along -X")


def _stopped(joints: Collector) -> bool:
    return max(abs(v) for v in joints.last().velocity) < 2e-3


# How far the arm runs on is judged in simulated time by tests/jog_arm/test_jog_arm_faults.py (killed: within
# 5 mm; hung: within 8 mm after incoming_cmd_timeout). Here, through the processes and in wall time, the arm
# must stop and stay stopped; SMOKE_BOUND allows a 0.3 s stall of a loaded machine at 5 cm/s on top.
SMOKE_BOUND = 0.025


@pytest.mark.parametrize("robot", ["ur5_custom", "panda_custom"])
def test_the_arm_stops_when_the_command_source_is_killed_or_hangs(ros_node, robot):
    with run_launch(robot, "sim.launch") as h:
        _stack(h)
        pose = Collector("/mujoco_driver/eef_pose", PoseStamped)
        joints = Collector("/joint_states", JointState)
        try:
            pose.wait_for(1, 20)
            joints.wait_for(1, 20)
            for how, sig in (("killed (Ctrl-C)", signal.SIGINT), ("hung (SIGSTOP)", signal.SIGSTOP)):
                with _readme_jog(robot) as proc:
                    _wait_for_travel(pose, 0.02)
                    start = pose.last()
                    _wait_for_travel(pose, 0.005)
                    speed = _speed_x(start, pose.last())  # in simulated time: load slows the clock too
                    os.killpg(proc.pid, sig)
                    stopped_at = time.monotonic()
                    wait_until(lambda: _stopped(joints), 10, "the arm to stop")
                    wait_until(lambda: _stopped(joints), 1, "the arm to stay stopped")
                    ran = float(np.linalg.norm(_tip(pose) - _tip_at(pose, stopped_at)))
                print(f"\n{robot}: jogging at {speed * 1e3:.0f} mm/s, source {how}: stopped after "
                      f"{ran * 1e3:.2f} mm")
                assert speed > 0.6 * SPEED
                assert ran <= SMOKE_BOUND, f"{how}: ran on {ran * 1e3:.1f} mm after the source vanished"
        finally:
            pose.close()
            joints.close()


def test_jog_arm_stops_commanding_when_the_driver_hangs_mid_jog(ros_node):
    """The driver freezes (SIGSTOP: its joint states stop, its connections stay). A crash is not tried here:
    sim.launch marks the driver required, so roslaunch then stops the whole stack; on a real cell the
    driver is a separate launch and jog_arm's joint_state_timeout is what stops the arm."""
    with run_launch("ur5_custom", "sim.launch") as h:
        _stack(h)
        status = Collector("/jog_arm_server/status", JogStatus)
        commands = Collector("/joint_group_velocity_controller/command", Float64MultiArray)
        pose = Collector("/mujoco_driver/eef_pose", PoseStamped)
        try:
            pose.wait_for(1, 20)
            with _readme_jog("ur5_custom"):
                _wait_for_travel(pose, 0.02)
                driver = node_pid("/mujoco_driver")
                os.kill(driver, signal.SIGSTOP)
                killed = time.monotonic()
                commands.clear()
                # Twists keep coming; without a joint state jog_arm decelerates to zero commands and says why.
                wait_until(lambda: commands.msgs and not any(commands.last().data), 10, "zero joint commands")
                halted = next(t for t, m in commands.timed() if not any(m.data))
                wait_until(lambda: status.last().code == JogStatus.STALE_JOINT_STATE, 5, "STALE_JOINT_STATE")
                assert "no joint state" in status.last().message
                os.kill(driver, signal.SIGCONT)
                print(f"\ndriver hung mid-jog: jog_arm's commands reached zero "
                      f"{(halted - killed) * 1e3:.0f} ms later ({status.last().message})")
        finally:
            with contextlib.suppress(NameError, ProcessLookupError):
                os.kill(driver, signal.SIGCONT)
            for c in (status, commands, pose):
                c.close()


def test_a_roscore_restart_stops_the_arm_and_the_stack_comes_back_by_itself(ros_node, roscore):
    rospy = ros_node
    with run_launch("ur5_custom", "sim.launch") as h:
        _stack(h)
        h.wait_for_service("/mujoco_driver/push", timeout=40)
        cc_status = Collector("/contact_control_node/status", ContactControlStatus)
        jog_status = Collector("/jog_arm_server/status", JogStatus)
        pose = Collector("/mujoco_driver/eef_pose", PoseStamped)
        # This test process registers again too, or the tests after it would talk to an empty master.
        watch = MasterWatch(lambda _reason: None, lambda: None, period=0.2)
        try:
            req = ConfigureForceControlRequest()
            req.cart_impedance_params.damping.translational.x = 200.0
            req.direction_control_laws.x.type = ControlLaw.TYPE_FOLLOWER
            assert rospy.ServiceProxy("/configure_cartesian_impedance", ConfigureForceControl)(req).success
            wait_until(lambda: bool(cc_status.last() and cc_status.last().move_active), 10, "a follower")

            lost = time.monotonic()
            roscore.stop()  # SIGINT, as Ctrl-C in its terminal

            def says_lost() -> bool:  # status still arrives: connections between nodes outlive the master
                return "ROS master" in cc_status.last().message and "master" in jog_status.last().message

            wait_until(says_lost, 10, "both parts to report the lost master")
            detected = min(t for t, m in cc_status.timed() if "ROS master" in m.message)
            assert not cc_status.last().move_active  # the move ended: the arm holds still
            assert jog_status.last().code == JogStatus.PAUSED
            assert h.proc.poll() is None, h.output()[-3000:]

            new = start_master(port=roscore.port, log_dir=roscore.env.get("ROS_LOG_DIR"))
            roscore.proc = new.proc
            back = time.monotonic()
            h.wait_for_service("/configure_cartesian_impedance", timeout=20)
            h.wait_for_service("/mujoco_driver/push", timeout=20)
            h.wait_for_topic("/joint_states", timeout=20)
            registered = time.monotonic()
            wait_until(lambda: "master" not in jog_status.last().message, 10, "jog_arm to resume")

            # Working again without a human: a follower gives way to a push.
            assert rospy.ServiceProxy("/configure_cartesian_impedance", ConfigureForceControl)(req).success
            wait_until(lambda: cc_status.last().move_active, 10, "the follower after the restart")
            before = _tip(pose)
            push = PushEEFRequest(duration=0.6)
            push.wrench.force.x = -10.0
            assert rospy.ServiceProxy("/mujoco_driver/push", PushEEF)(push).success
            wait_until(lambda: before[0] - _tip(pose)[0] > 0.01, 10, "the tool to follow the push along -X")
            print(f"\nroscore restart: loss reported {(detected - lost):.2f} s after it died; the stack's "
                  f"services were registered again {registered - back:.2f} s after the new master started")
        finally:
            watch.close()
            for c in (cc_status, jog_status, pose):
                c.close()


def test_a_request_re_sent_at_100_hz_during_a_push_does_not_change_the_motion(ros_node):
    """A GUI's Apply held down, a script in a loop: the same follower request 100 times a second while a
    5 N push lasts. Each used to restart the axes from rest (0.7 mm instead of 21 mm); now nothing changes."""
    import threading

    rospy = ros_node
    with run_launch("ur5_custom", "sim.launch") as h:
        _stack(h)
        h.wait_for_service("/mujoco_driver/push", timeout=40)
        pose = Collector("/mujoco_driver/eef_pose", PoseStamped)
        joints = Collector("/joint_states", JointState)
        req = ConfigureForceControlRequest()
        req.cart_impedance_params.damping.translational.z = 30.0  # the thesis's b: 5 N -> 0.17 m/s
        req.direction_control_laws.z.type = ControlLaw.TYPE_FOLLOWER
        configure = rospy.ServiceProxy(
            "/configure_cartesian_impedance", ConfigureForceControl, persistent=True
        )
        push_srv = rospy.ServiceProxy("/mujoco_driver/push", PushEEF)
        status = Collector("/contact_control_node/status", ContactControlStatus)
        jogging = Collector("/jog_arm_server/status", JogStatus)
        try:
            pose.wait_for(1, 20)
            joints.wait_for(1, 20)
            # contact_control is processing wrenches (tared, data fresh) before the laws are set: pushing
            # within ~50 ms of start-up, before its first wrench, sometimes latched it at 237-262 N (see
            # contact_control's README, Known limits)
            wait_until(lambda: status.last() is not None and status.last().safety == 0, 20,
                       "contact_control to process wrenches")
            assert configure(req).success

            def pushed(fz: float, spam: bool) -> tuple[float, int]:
                """Z travel [m] under a 0.4 s push of `fz` N, and how many requests were re-sent meanwhile"""
                wait_until(lambda: _stopped(joints), 10, "the arm at rest")
                z0 = _tip(pose)[2]
                stop, sent = threading.Event(), [0]

                def resend() -> None:
                    while not stop.wait(0.01):
                        answer = configure(req)
                        if not answer.success:  # said in the pair's line, not lost in a thread
                            refused.append(answer.error)
                            return
                        sent[0] += 1

                thread = threading.Thread(target=resend, daemon=True)
                if spam:
                    thread.start()
                push = PushEEFRequest(duration=0.4)
                push.wrench.force.z = fz
                pushed_at = pose.last().header.stamp
                assert push_srv(push).success
                # Past the push's end (the driver's time) before judging rest: the arm is at rest for a while
                # after the push begins, until the filtered force passes the deadband (on a loaded machine the
                # first motion was a push's early twitch, the follower's travel landing in the next push).
                ended = pushed_at + rospy.Duration(push.duration + 0.1)
                wait_until(lambda: pose.last().header.stamp >= ended, 10, "the push to end")
                wait_until(lambda: _stopped(joints), 10, "the arm to stop after the push")
                stop.set()
                if spam:
                    thread.join()
                return _tip(pose)[2] - z0, sent[0]

            # A restart from rest on every request cut the travel 30-fold (0.7 vs 21 mm before the fix); a
            # third off is well outside what load does to a correct stack. Load does change both pushes: a VM
            # stall lets the arm run on (35.0 vs 40.1 mm once in CI; the 0.2 mm pushes CI also saw were the
            # measurement ending at a push's first twitch, fixed above), and a starved client re-sent only
            # 4-41 times in a push (about 40 when quiet; 10 restarts would leave about 12 % of the
            # travel, from the first-order ramp that 0.7 of 21 mm at 100 Hz implies). So a pair is repeated,
            # at most 3 times, all printed. A starved machine can also stall the wrenches or joint states long
            # enough to end the follower or get a re-sent request refused: the stack doing its job, which
            # spoils the pair for this comparison. Such a pair is named (contact_control's and jog_arm's
            # status) and repeated.
            for _ in range(3):
                refused: list[str] = []
                status.clear()
                jogging.clear()
                quiet, _ = pushed(5.0, spam=False)
                pushed(-5.0, spam=False)  # back down
                spammed, sent = pushed(5.0, spam=True)
                pushed(-5.0, spam=False)
                faults = {(m.safety_name, m.message) for _, m in status.timed()
                          if m.safety or not m.move_active}
                # jog_arm's halts (stale or missing joint states, paused, a bad command): the stack's job
                # (STALE_COMMAND is its idle state between pushes).
                halts = (JogStatus.NO_JOINT_STATE, JogStatus.STALE_JOINT_STATE, JogStatus.PAUSED,
                         JogStatus.INVALID_COMMAND)
                faults |= {(m.code_name, m.message) for _, m in jogging.timed() if m.code in halts}
                print(f"\nfollower under a 5 N push: {quiet * 1e3:.1f} mm; with the request re-sent {sent} "
                      f"times meanwhile: {spammed * 1e3:.1f} mm; refused {refused}; stack faults {faults}")
                if faults or refused:
                    assert configure(req).success, faults  # the follower again after the stall ended it
                    continue
                if quiet > 0.01 and sent >= 10 and spammed == pytest.approx(quiet, rel=0.30):
                    break
            assert not faults and not refused, "every pair was spoilt by a stalled stack"
            assert quiet > 0.01, h.output()[-3000:]
            assert sent >= 10
            assert spammed == pytest.approx(quiet, rel=0.30), h.output()[-4000:]
        finally:
            configure.close()
            status.close()
            jogging.close()
            pose.close()
            joints.close()
