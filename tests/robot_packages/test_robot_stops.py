"""End to end, the robot's own stop (jog_arm README, *Robot stops*): each robot package's hardware.launch,
unchanged, on mujoco_driver's emulation of its real driver. A push on the tool in the middle of a compliant
move (a follower giving way) trips the driver's own stop: the UR's protective stop (its safety limit set to
40 N here), the Panda's collision reflex (franka_hw's default 20 N).

The stack notices within a cycle: jog_arm holds and says why (status, /diagnostics ERROR), contact_control's
move ends with the reason and new requests are refused; jog twists move nothing. ``jog_arm_server/recover``
answers why it cannot while the driver refuses (the UR's dashboard refuses an unlock for 3 s here); then it
runs the driver's recovery, and commands move the arm again from where it was held, without a jump. A
named-pose move cut by a stop answers at once."""

from __future__ import annotations

import threading

import numpy as np
import pytest

pytest.importorskip("ur_dashboard_msgs.msg", reason="needs devel/setup.bash (make test sources it)")

from cartesian_impedance_msgs.msg import ControlLaw
from cartesian_impedance_msgs.srv import ConfigureForceControl, ConfigureForceControlRequest
from compliant_control_msgs.msg import ContactControlStatus, ContactEvent, JogStatus
from compliant_control_msgs.srv import MoveToNamedPose, PushEEF, PushEEFRequest
from controller_manager_msgs.srv import SwitchController, SwitchControllerRequest
from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus
from geometry_msgs.msg import PoseStamped, TwistStamped, Wrench
from harness.launch import run_launch
from harness.waiting import Collector, wait_until
from std_msgs.msg import String
from std_srvs.srv import Trigger

pytestmark = pytest.mark.cobot_safety

UNLOCK_AFTER = 3.0  # [s] the UR's dashboard refuses an unlock before this
UR_OPTIONS = f"{{protective_stop_force: 40.0, protective_stop_unlock_after: {UNLOCK_AFTER}}}"
JOG = 0.05  # [m/s]
# Per robot: the emulated driver, the base frame, the stop's name in the driver's words, the push that trips
# it [N] (the follower's own push is a quarter of it), whether the UR's dashboard wait applies, the
# controller switch jog_arm needs (README *Real robot*) and the joint states.
CELLS = {
    "ur5_custom": dict(profile="ur_robot_driver", base="base_link", stop="PROTECTIVE_STOP", push=80.0,
                       options=UR_OPTIONS,
                       switch=("joint_group_vel_controller", "scaled_pos_joint_traj_controller"),
                       joints="/joint_states"),
    "panda_custom": dict(profile="franka_ros", base="panda_link0", stop="ROBOT_MODE_REFLEX", push=40.0,
                         options="{}", switch=None, joints="/franka_state_controller/joint_states"),
}


def _speeds(poses: list, window: float) -> np.ndarray:
    """The tip's mean speed over each ``window`` [s] of ROS time (eef_pose stamps)."""
    tips = np.array([_tip(m) for m in poses])
    stamps = np.array([m.header.stamp.to_sec() for m in poses])
    later = np.searchsorted(stamps, stamps + window)
    first = np.flatnonzero(later < len(stamps))
    last = later[first]
    return np.linalg.norm(tips[last] - tips[first], axis=1) / (stamps[last] - stamps[first])


def _tip(msg) -> np.ndarray:
    p = msg.pose.position
    return np.array([p.x, p.y, p.z])


def _force(x: float) -> Wrench:
    w = Wrench()
    w.force.x = x
    return w


@pytest.mark.parametrize("robot", list(CELLS))
def test_a_drivers_stop_mid_move_holds_explains_and_resumes_without_a_jump(ros_node, robot):
    rospy = ros_node
    cell = CELLS[robot]
    args = {"robot_package": robot, "profile": cell["profile"], "profile_options": cell["options"]}
    with run_launch("mujoco_driver", "emulated_robot.launch", args=args) as driver:
        driver.wait_for_topic(cell["joints"], timeout=40)
        with run_launch(robot, "hardware.launch") as stack:
            for name in ("/configure_cartesian_impedance", "/named_poses/move_to", "/jog_arm_server/recover"):
                stack.wait_for_service(name, timeout=40)
            _Cell(rospy, cell).run()
            stack.stop()
            assert stack.proc.returncode == 0, stack.output()[-3000:]
        driver.stop()
        assert driver.proc.returncode == 0, driver.output()[-3000:]


class _Cell:
    """The test's ends on the running cell."""

    def __init__(self, rospy, cell: dict) -> None:
        self.rospy, self.cell = rospy, cell
        self.poses = Collector("/mujoco_driver/eef_pose", PoseStamped, queue_size=100000)
        self.jog = Collector("/jog_arm_server/status", JogStatus, queue_size=100000)
        self.cc = Collector("/contact_control_node/status", ContactControlStatus)
        self.events = Collector("/contact_control_node/events", ContactEvent)
        self.diagnostics = Collector("/diagnostics", DiagnosticArray, queue_size=10000)
        self.stop_topic = Collector("/jog_arm_server/robot_stop", String)
        self.pub = rospy.Publisher("/jog_arm_server/delta_jog_cmds", TwistStamped, queue_size=1,
                                   tcp_nodelay=True)
        self.push = rospy.ServiceProxy("/mujoco_driver/push", PushEEF)
        self.recover = rospy.ServiceProxy("/jog_arm_server/recover", Trigger)
        self.configure = rospy.ServiceProxy("/configure_cartesian_impedance", ConfigureForceControl)
        self.move_to = rospy.ServiceProxy("/named_poses/move_to", MoveToNamedPose)

    def run(self) -> None:
        try:
            self._run()
        finally:
            for c in (self.poses, self.jog, self.cc, self.events, self.diagnostics, self.stop_topic):
                c.close()
            self.pub.unregister()

    def _jog(self, count: int) -> None:
        twist = TwistStamped()
        twist.header.frame_id = self.cell["base"]
        twist.twist.linear.x = -JOG
        rate = self.rospy.Rate(50)
        for _ in range(count):
            twist.header.stamp = self.rospy.Time.now()
            self.pub.publish(twist)
            rate.sleep()  # the sender's rate, not a wait for a result

    def _stopped_after(self, before: int) -> float:
        """The stamp of jog_arm's first ROBOT_STOPPED status after message ``before``, waiting for it; within
        0.5 s of it the status names the stop's cause (the UR's program state may bring the news first)."""
        def seen() -> bool:
            return any(m.code == JogStatus.ROBOT_STOPPED for m in self.jog.msgs[before:])

        wait_until(seen, 10, "jog_arm to report the robot stopped")
        first = next(m for m in self.jog.msgs[before:] if m.code == JogStatus.ROBOT_STOPPED)
        t_stop = first.header.stamp.to_sec()

        def named() -> bool:
            return any(m.code == JogStatus.ROBOT_STOPPED and self.cell["stop"] in m.message
                       and m.header.stamp.to_sec() <= t_stop + 0.5 for m in self.jog.msgs[before:])

        wait_until(named, 5, f"jog_arm's status to name {self.cell['stop']}")
        return t_stop

    def _recover_when_allowed(self, t_stop: float) -> None:
        if self.cell["profile"] == "ur_robot_driver":  # the dashboard's wait
            wait_until(lambda: self.rospy.get_time() > t_stop + UNLOCK_AFTER + 0.1, 10, "the unlock wait")
        answer = self.recover()
        assert answer.success, answer.message
        wait_until(lambda: self.stop_topic.last().data == "", 5, "~robot_stop cleared")

    def _run(self) -> None:
        rospy, cell = self.rospy, self.cell
        for c in (self.poses, self.jog, self.cc, self.stop_topic):
            c.wait_for(1, timeout=20)
        assert self.stop_topic.last().data == ""
        if cell["switch"]:  # the README's *Real robot* step: jog_arm's velocity controller on
            start, stop = cell["switch"]
            req = SwitchControllerRequest(start_controllers=[start], stop_controllers=[stop],
                                          strictness=SwitchControllerRequest.STRICT)
            assert rospy.ServiceProxy("/controller_manager/switch_controller", SwitchController)(req).ok
        ok = lambda: self.cc.last().safety == ContactControlStatus.SAFETY_OK  # noqa: E731
        wait_until(ok, 20, "the sensor to be zeroed")
        # A compliant move: a follower along X gives way to a push (b = 200 N s/m).
        law = ConfigureForceControlRequest()
        law.cart_impedance_params.damping.translational.x = 200.0
        law.direction_control_laws.x.type = ControlLaw.TYPE_FOLLOWER
        assert self.configure(law).success
        wait_until(lambda: self.cc.last().move_active, 5, "the follower to be active")
        start = _tip(self.poses.last())
        assert self.push(PushEEFRequest(wrench=_force(-cell["push"] / 4), duration=2.0)).success
        wait_until(lambda: start[0] - _tip(self.poses.last())[0] > 0.01, 10, "the follower to give way")
        before = len(self.jog.msgs)
        assert self.push(PushEEFRequest(wrench=_force(-cell["push"]), duration=0.2)).success
        t_stop = self._stopped_after(before)
        if cell["profile"] == "ur_robot_driver":
            # Asked to recover at once: the dashboard refuses the unlock; the answer says so, nothing moves.
            early = self.recover()
            assert not early.success and "Cannot unlock protective stop" in early.message, early.message
        # contact_control's move ended with the reason; a new request is refused, a named-pose move too.
        # (its event carries the first news: the UR's program state may come before the safety mode). The
        # push is over contact_control's own global limit (25 N) too, which fires 2 ms after the stop: on a
        # loaded machine it can come first, and the move then ends naming the limit (the stop ends no move
        # after it).
        def ended() -> list[str]:
            return [e.message for e in self.events.msgs if e.type == ContactEvent.MOVE_ENDED]

        wait_until(ended, 5, "contact_control's move to end")
        why = ended()[0]
        assert "the robot stopped" in why or "over the global limit" in why, ended()
        print(f"\nthe move ended: {why}")
        wait_until(lambda: not self.cc.last().move_active, 5, "contact_control's status to show no move")
        assert not self.configure(law).success
        moved = self.move_to(name="home", speed_scale=1.0)
        assert not moved.success and cell["stop"] in moved.message, moved.message

        def named() -> bool:  # /diagnostics names the stop within 1 s
            return any(s.level == DiagnosticStatus.ERROR and cell["stop"] in s.message and "jog_arm" in s.name
                       and a.header.stamp.to_sec() - t_stop <= 1.0
                       for a in self.diagnostics.msgs for s in a.status)

        wait_until(named, 10, "/diagnostics to name the stop")

        def contact_control_says() -> bool:  # and contact_control why it refuses (WARN, or worse beside it)
            return any(s.level >= DiagnosticStatus.WARN and "contact_control" in s.name
                       and any(v.key == "robot" and cell["stop"] in v.value for v in s.values)
                       for a in self.diagnostics.msgs for s in a.status)

        wait_until(contact_control_says, 10, "contact_control's /diagnostics to name the stop")
        # Standstill within 0.3 s, and jogs move nothing while stopped.
        wait_until(lambda: self.poses.last().header.stamp.to_sec() > t_stop + 0.5, 10, "0.5 s after the stop")
        self._jog(25)
        after = [m for m in self.poses.msgs if m.header.stamp.to_sec() >= t_stop + 0.3]
        speeds = _speeds(after, 0.05)
        print(f"\nstopped at t={t_stop:.3f} s; tip speed 0.3 s on at most {speeds.max() * 1e3:.2f} mm/s")
        assert speeds.max() < 0.002, "the arm still moved 0.3 s after the stop"
        assert self.jog.last().code == JogStatus.ROBOT_STOPPED
        held = _tip(self.poses.last())
        self._recover_when_allowed(t_stop)
        t_recovered = rospy.get_time()
        self._jog(40)
        resumed = [m for m in self.poses.msgs if m.header.stamp.to_sec() >= t_recovered]
        moved_by = held - _tip(self.poses.last())
        speeds = _speeds(resumed, 0.02)
        print(f"recovered; jogged {moved_by[0] * 1e3:.1f} mm, peak 20 ms speed {speeds.max() * 1e3:.1f} mm/s")
        assert moved_by[0] > 0.01, f"the arm did not jog after recovery: {moved_by}"
        assert speeds.max() < 1.5 * JOG  # no jump: a 2 mm step would add 0.1 m/s to a 20 ms mean
        assert np.linalg.norm(_tip(resumed[0]) - held) < 0.002
        # The push also latched contact_control's own global force limit: reset it, as a user would.
        assert rospy.ServiceProxy("/contact_control_node/reset", Trigger)().success
        assert self.configure(law).success, self.cc.last().message  # requests are taken again
        assert rospy.ServiceProxy("/contact_control_node/stop", Trigger)().success
        self._named_move_cut_short()

    def _named_move_cut_short(self) -> None:
        """A named-pose move (a trajectory the driver runs, jog_arm paused) stopped on the way: the service
        answers at once naming the stop; after recovery the arm is where it was held."""
        wait_until(lambda: self.jog.last().code != JogStatus.ROBOT_STOPPED, 5, "jog_arm to run")
        answers: list = []
        mover = threading.Thread(target=lambda: answers.append(self.move_to(name="home", speed_scale=0.5)))
        start = _tip(self.poses.last())
        mover.start()
        wait_until(lambda: np.linalg.norm(_tip(self.poses.last()) - start) > 0.01, 10, "the move to start")
        before = len(self.jog.msgs)
        assert self.push(PushEEFRequest(wrench=_force(-self.cell["push"]), duration=0.2)).success
        mover.join(timeout=10)
        assert answers and not answers[0].success, answers
        assert "stopped on the way to 'home'" in answers[0].message, answers[0].message
        assert self.cell["stop"] in answers[0].message
        t_stop = self._stopped_after(before)
        wait_until(lambda: self.rospy.get_time() > t_stop + 0.5, 10, "the arm to settle")
        held = _tip(self.poses.last())
        self._recover_when_allowed(t_stop)
        self.rospy.sleep(0.3)
        print(f"named move stopped: {answers[0].message}")
        assert np.linalg.norm(_tip(self.poses.last()) - held) < 0.002  # recovery moved nothing
