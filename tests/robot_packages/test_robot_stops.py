"""End to end, the robot's own stop (jog_arm README, *Robot stops*): the UR5's hardware.launch, unchanged, on
mujoco_driver's emulation of ur_robot_driver, whose safety system's force limit is set low (40 N) so that a
push on the tool trips a protective stop in the middle of a compliant move (a follower giving way).

The stack notices within a cycle: jog_arm holds and says why (status, /diagnostics ERROR), contact_control's
move ends with the reason and new requests are refused; jog twists move nothing. ``jog_arm_server/recover``
first answers why it cannot (the dashboard refuses an unlock for 3 s here); once it may, it unlocks, restarts
the program, and commands move the arm again from where it was held, without a jump."""

from __future__ import annotations

import numpy as np
import pytest

pytest.importorskip("ur_dashboard_msgs.msg", reason="needs devel/setup.bash (make test sources it)")

from cartesian_impedance_msgs.msg import ControlLaw
from cartesian_impedance_msgs.srv import ConfigureForceControl, ConfigureForceControlRequest
from compliant_control_msgs.msg import ContactControlStatus, ContactEvent, JogStatus
from compliant_control_msgs.srv import MoveToNamedPose, PushEEF, PushEEFRequest
from controller_manager_msgs.srv import SwitchController, SwitchControllerRequest
from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus
from geometry_msgs.msg import PoseStamped, TwistStamped
from harness.launch import run_launch
from harness.waiting import Collector, wait_until
from std_msgs.msg import String
from std_srvs.srv import Trigger

pytestmark = pytest.mark.cobot_safety

LIMIT = 40.0  # [N] the emulated safety configuration's TCP force limit
UNLOCK_AFTER = 3.0  # [s] the dashboard refuses an unlock before this
JOG = 0.05  # [m/s]


def _speeds(poses: list, window: float) -> np.ndarray:
    """The tip's mean speed over each ``window`` [s] of simulated time (eef_pose stamps)."""
    tips = np.array([[m.pose.position.x, m.pose.position.y, m.pose.position.z] for m in poses])
    stamps = np.array([m.header.stamp.to_sec() for m in poses])
    later = np.searchsorted(stamps, stamps + window)
    first = np.flatnonzero(later < len(stamps))
    last = later[first]
    return np.linalg.norm(tips[last] - tips[first], axis=1) / (stamps[last] - stamps[first])


def _tip(msg) -> np.ndarray:
    p = msg.pose.position
    return np.array([p.x, p.y, p.z])


def _jog(rospy, pub, count: int) -> None:
    twist = TwistStamped()
    twist.header.frame_id = "base_link"
    twist.twist.linear.x = -JOG
    rate = rospy.Rate(50)
    for _ in range(count):
        twist.header.stamp = rospy.Time.now()
        pub.publish(twist)
        rate.sleep()  # the sender's rate, not a wait for a result


def test_a_protective_stop_mid_move_holds_explains_and_resumes_without_a_jump(ros_node):
    rospy = ros_node
    options = f"{{protective_stop_force: {LIMIT}, protective_stop_unlock_after: {UNLOCK_AFTER}}}"
    args = {"robot_package": "ur5_custom", "profile": "ur_robot_driver", "profile_options": options}
    with run_launch("mujoco_driver", "emulated_robot.launch", args=args) as driver:
        driver.wait_for_topic("/joint_states", timeout=40)
        with run_launch("ur5_custom", "hardware.launch") as stack:
            stack.wait_for_service("/configure_cartesian_impedance", timeout=40)
            stack.wait_for_service("/named_poses/move_to", timeout=40)
            stack.wait_for_service("/jog_arm_server/recover", timeout=40)
            _run(rospy, driver)
            stack.stop()
            assert stack.proc.returncode == 0, stack.output()[-3000:]
        driver.stop()
        assert driver.proc.returncode == 0, driver.output()[-3000:]


def _run(rospy, driver) -> None:
    poses = Collector("/mujoco_driver/eef_pose", PoseStamped, queue_size=100000)
    jog = Collector("/jog_arm_server/status", JogStatus, queue_size=100000)
    cc = Collector("/contact_control_node/status", ContactControlStatus)
    events = Collector("/contact_control_node/events", ContactEvent)
    diagnostics = Collector("/diagnostics", DiagnosticArray, queue_size=10000)
    stop_topic = Collector("/jog_arm_server/robot_stop", String)
    pub = rospy.Publisher("/jog_arm_server/delta_jog_cmds", TwistStamped, queue_size=1, tcp_nodelay=True)
    try:
        for c in (poses, jog, cc, stop_topic):
            c.wait_for(1, timeout=20)
        assert stop_topic.last().data == ""
        # The README's *Real robot* step: jog_arm's velocity controller on.
        req = SwitchControllerRequest(start_controllers=["joint_group_vel_controller"],
                                      stop_controllers=["scaled_pos_joint_traj_controller"],
                                      strictness=SwitchControllerRequest.STRICT)
        assert rospy.ServiceProxy("/controller_manager/switch_controller", SwitchController)(req).ok
        wait_until(lambda: cc.last().safety == ContactControlStatus.SAFETY_OK, 20, "the sensor to be zeroed")
        # A compliant move: a follower along X gives way to a 20 N push (b = 200 N s/m: 0.1 m/s).
        law = ConfigureForceControlRequest()
        law.cart_impedance_params.damping.translational.x = 200.0
        law.direction_control_laws.x.type = ControlLaw.TYPE_FOLLOWER
        configure = rospy.ServiceProxy("/configure_cartesian_impedance", ConfigureForceControl)
        assert configure(law).success
        wait_until(lambda: cc.last().move_active, 5, "the follower to be active")
        push = rospy.ServiceProxy("/mujoco_driver/push", PushEEF)
        start = _tip(poses.last())
        assert push(PushEEFRequest(wrench=_force(-20.0), duration=2.0)).success
        wait_until(lambda: start[0] - _tip(poses.last())[0] > 0.01, 10, "the follower to give way")
        assert push(PushEEFRequest(wrench=_force(-2.0 * LIMIT), duration=0.2)).success  # over the limit
        stopped = lambda: any(m.code == JogStatus.ROBOT_STOPPED for m in jog.msgs)  # noqa: E731
        wait_until(stopped, 10, "jog_arm to report the robot stopped")
        first = next(m for m in jog.msgs if m.code == JogStatus.ROBOT_STOPPED)
        t_stop = first.header.stamp.to_sec()
        assert "PROTECTIVE_STOP" in first.message, first.message
        # Asked to recover at once: the dashboard refuses the unlock; the answer says so, nothing moves.
        recover = rospy.ServiceProxy("/jog_arm_server/recover", Trigger)
        early = recover()
        assert not early.success and "Cannot unlock protective stop" in early.message, early.message
        # contact_control's move ended with the reason; a new request is refused.
        ended = lambda: any(e.type == ContactEvent.MOVE_ENDED and "PROTECTIVE_STOP" in e.message  # noqa: E731
                            for e in events.msgs)
        wait_until(ended, 5, "contact_control's move to end naming the stop")
        wait_until(lambda: not cc.last().move_active, 5, "contact_control's status to show no move")
        assert not configure(law).success
        moved = rospy.ServiceProxy("/named_poses/move_to", MoveToNamedPose)(name="home", speed_scale=1.0)
        assert not moved.success and "PROTECTIVE_STOP" in moved.message, moved.message
        # /diagnostics names it within 1 s (simulated time).
        def named() -> bool:
            return any(s.level == DiagnosticStatus.ERROR and "PROTECTIVE_STOP" in s.message
                       and "jog_arm" in s.name and a.header.stamp.to_sec() - t_stop <= 1.0
                       for a in diagnostics.msgs for s in a.status)
        wait_until(named, 10, "/diagnostics to name the protective stop")
        # Standstill within 0.3 s, and jogs move nothing while stopped.
        wait_until(lambda: poses.last().header.stamp.to_sec() > t_stop + 0.5, 10, "0.5 s after the stop")
        _jog(rospy, pub, 25)
        after = [m for m in poses.msgs if m.header.stamp.to_sec() >= t_stop + 0.3]
        speeds = _speeds(after, 0.05)
        print(f"\nstopped at t={t_stop:.3f} s; tip speed 0.3 s on at most {speeds.max() * 1e3:.2f} mm/s")
        assert speeds.max() < 0.002, "the arm still moved 0.3 s after the protective stop"
        assert jog.last().code == JogStatus.ROBOT_STOPPED
        wait_until(lambda: rospy.get_time() > t_stop + UNLOCK_AFTER + 0.05, 10, "the unlock wait")
        held = _tip(poses.last())
        answer = recover()
        assert answer.success, answer.message
        wait_until(lambda: stop_topic.last().data == "", 5, "~robot_stop cleared")
        t_recovered = rospy.get_time()
        _jog(rospy, pub, 40)
        resumed = [m for m in poses.msgs if m.header.stamp.to_sec() >= t_recovered]
        moved = held - _tip(poses.last())
        speeds = _speeds(resumed, 0.02)
        print(f"recovered: {answer.message}; jogged {moved[0] * 1e3:.1f} mm, peak 20 ms speed "
              f"{speeds.max() * 1e3:.1f} mm/s")
        assert moved[0] > 0.01, f"the arm did not jog after recovery: {moved}"
        # No jump: a 2 mm step would add 0.1 m/s to a 20 ms mean.
        assert speeds.max() < 1.5 * JOG
        assert np.linalg.norm(_tip(resumed[0]) - held) < 0.002
        # The 80 N push also latched contact_control's own global force limit: reset it, as a user would.
        assert rospy.ServiceProxy("/contact_control_node/reset", Trigger)().success
        assert configure(law).success, cc.last().message  # contact_control takes requests again
        assert rospy.ServiceProxy("/contact_control_node/stop", Trigger)().success
        _named_move_cut_short(rospy, poses, jog, push, recover, stop_topic)
    finally:
        for c in (poses, jog, cc, events, diagnostics, stop_topic):
            c.close()
        pub.unregister()


def _named_move_cut_short(rospy, poses, jog, push, recover, stop_topic) -> None:
    """A named-pose move (a trajectory the driver runs, jog_arm paused) stopped on the way: the service
    answers at once naming the stop; after recovery the arm is where it was held."""
    import threading

    wait_until(lambda: jog.last().code != JogStatus.ROBOT_STOPPED, 5, "jog_arm to run")
    answers: list = []
    move_to = rospy.ServiceProxy("/named_poses/move_to", MoveToNamedPose)
    mover = threading.Thread(target=lambda: answers.append(move_to(name="home", speed_scale=0.5)))
    start = _tip(poses.last())
    mover.start()
    wait_until(lambda: np.linalg.norm(_tip(poses.last()) - start) > 0.01, 10, "the named-pose move to start")
    before = len(jog.msgs)
    assert push(PushEEFRequest(wrench=_force(-2.0 * LIMIT), duration=0.2)).success
    mover.join(timeout=10)
    assert answers and not answers[0].success, answers
    assert "stopped on the way to 'home'" in answers[0].message and "PROTECTIVE_STOP" in answers[0].message
    wait_until(lambda: any(m.code == JogStatus.ROBOT_STOPPED for m in jog.msgs[before:]), 5, "ROBOT_STOPPED")
    t_stop = next(m for m in jog.msgs[before:] if m.code == JogStatus.ROBOT_STOPPED).header.stamp.to_sec()
    wait_until(lambda: rospy.get_time() > t_stop + UNLOCK_AFTER + 0.1, 10, "the unlock wait")
    held = _tip(poses.last())
    answer = recover()
    assert answer.success, answer.message
    wait_until(lambda: stop_topic.last().data == "", 5, "~robot_stop cleared")
    rospy.sleep(0.3)
    print(f"named move stopped: {answers[0].message}")
    assert np.linalg.norm(_tip(poses.last()) - held) < 0.002  # recovery moved nothing


def _force(x: float):
    from geometry_msgs.msg import Wrench

    w = Wrench()
    w.force.x = x
    return w
