"""control_stack_node under sim time when the clock jumps (a simulator restarted, a bag looped with --clock):
both parts halt, say so on their status topics, keep every thread and timer alive, and resume with data
stamped after the jump."""

from __future__ import annotations

import pathlib
import sys
import threading
import time

import pytest

pytest.importorskip("cartesian_impedance_msgs.srv", reason="needs devel/setup.bash (make test sources it)")

from cartesian_impedance_msgs.srv import ConfigureForceControl, ConfigureForceControlRequest
from compliant_control_msgs.msg import ContactControlStatus, JogStatus
from geometry_msgs.msg import TwistStamped, WrenchStamped
from harness.launch import run_node
from harness.waiting import Collector, wait_until
from rosgraph_msgs.msg import Clock
from sensor_msgs.msg import JointState
from std_msgs.msg import Float64MultiArray

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parents[1] / "jog_arm"))
from jog_arm_testing import UR5

from jog_arm import ArmModel

NS = "/cs_clock"
TWIST, COMMAND = f"{NS}/jog_arm_server/delta_jog_cmds", f"{NS}/command"
JOG = {
    "ee_frame_name": UR5.tip, "planning_frame": "base_link", "command_in_type": "speed_units",
    "joint_topic": "joint_states", "cmd_in_topic": "jog_arm_server/delta_jog_cmds",
    "cmd_out_topic": "command",
    "command_out_type": "velocity_array", "integrate_from": "measured", "publish_on_command": True,
    "pub_period": 0.005, "incoming_cmd_timeout": 0.5, "joint_state_timeout": 0.2,
}
CONTACT = {
    "ft_in_topic": "wrench", "velocity_out_topic": "jog_arm_server/delta_jog_cmds", "tare_on_startup": False,
    "lp_filter_enabled": False, "eef_frame": "base_link", "wrench_timeout": 0.2, "no_data_end_timeout": 30.0,
    "status_rate": 50.0,
}
PERIOD = 0.005  # [s] of the simulated cell: clock, wrench and joint state every 5 ms


class SimCell:
    """Publishes /clock, a 10 N push along Z stamped with that clock, and the arm's joint state."""

    def __init__(self, rospy) -> None:
        self._rospy = rospy
        self.clock = rospy.Publisher("/clock", Clock, queue_size=1, tcp_nodelay=True)
        self.wrench = rospy.Publisher(f"{NS}/wrench", WrenchStamped, queue_size=1, tcp_nodelay=True)
        self.joints = rospy.Publisher(f"{NS}/joint_states", JointState, queue_size=1, tcp_nodelay=True)
        self.sim = 1000.0
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._run, daemon=True)
        self._names = list(ArmModel(UR5.urdf, UR5.tip).joint_names)

    def start(self) -> None:
        self._thread.start()

    def jump(self, seconds: float) -> None:
        self.sim += seconds

    def _run(self) -> None:
        Time = self._rospy.Time
        w = WrenchStamped()
        w.header.frame_id = "base_link"
        w.wrench.force.z = 10.0
        state = JointState(name=self._names, position=list(UR5.start))
        while not self._stop.is_set():
            self.sim += PERIOD
            now = Time.from_sec(self.sim)
            self.clock.publish(Clock(clock=now))
            w.header.stamp = state.header.stamp = now
            self.joints.publish(state)
            self.wrench.publish(w)
            time.sleep(PERIOD)

    def stop(self) -> None:
        self._stop.set()
        self._thread.join()
        for pub in (self.clock, self.wrench, self.joints):
            pub.unregister()


def test_clock_jumps_back_and_forward_halt_both_parts_which_then_resume(ros_node):
    rospy = ros_node
    rospy.set_param("/use_sim_time", True)
    rospy.set_param(f"{NS}/robot_description", UR5.urdf)
    rospy.set_param(f"{NS}/jog_arm_server", JOG)
    rospy.set_param(f"{NS}/contact_control_node", CONTACT)
    cell = SimCell(rospy)
    twists, commands = Collector(TWIST, TwistStamped), Collector(COMMAND, Float64MultiArray)
    cc_status = Collector(f"{NS}/contact_control_node/status", ContactControlStatus)
    jog_status = Collector(f"{NS}/jog_arm_server/status", JogStatus)
    try:
        cell.start()
        with run_node("control_stack", "control_stack_node", args=[f"__ns:={NS}"]) as h:
            h.wait_for_service(f"{NS}/configure_cartesian_impedance", timeout=30)
            req = ConfigureForceControlRequest()
            req.direction_control_laws.z.type = 1  # follower, b = 50: 10 N -> 0.2 m/s
            req.cart_impedance_params.damping.translational.z = 50.0
            configure = rospy.ServiceProxy(f"{NS}/configure_cartesian_impedance", ConfigureForceControl)
            assert configure(req).success, h.output()[-2000:]

            def moving() -> bool:
                last = commands.last()
                return last is not None and any(last.data)

            def wait(predicate, what: str) -> None:
                try:
                    wait_until(predicate, 10, what)
                except AssertionError as err:
                    raise AssertionError(f"{err}\n{h.output()[-3000:]}") from None

            wait(moving, "joint commands for the push")
            for jump in (-5.0, 5.0):
                wait(lambda: len(commands.msgs) > 20, "steady commands")
                speed = max(abs(v) for v in commands.last().data)
                twists.clear()
                commands.clear()
                cc_status.clear()
                jog_status.clear()
                cell.jump(jump)
                # contact_control halts at once (a zero twist); jog_arm drops the command and slows down
                # within its acceleration limits until fresh data (5 ms later here) moves it again.
                def zero_twist() -> bool:
                    return any(m.twist.linear.z == 0.0 for m in list(twists.msgs))

                try:
                    wait_until(zero_twist, 10, f"a zero twist ({jump} s)")
                except AssertionError as err:  # what came instead: a twist lost, or none at all
                    came = [round(m.twist.linear.z, 4) for m in list(twists.msgs)[:8]]
                    got = f"since the jump {len(twists.msgs)} twists (z {came}), {len(commands.msgs)} cmds"
                    raise AssertionError(f"{err}; {got}\n{h.output()[-3000:]}") from None
                wait(lambda: len(commands.msgs) > 20, "commands after the jump")
                slowest = min(max(abs(v) for v in m.data) for m in list(commands.msgs)[:20])
                assert slowest < 0.8 * speed, (slowest, speed)
                def reported(collector) -> bool:
                    return any("clock jump" in m.message for m in list(collector.msgs))

                wait(lambda: reported(cc_status), "contact_control's status to report the jump")
                wait(lambda: reported(jog_status), "jog_arm's status to report the jump")
                # ... and both resume with fresh data: nonzero twists and commands, status still running.
                twists.clear()
                commands.clear()
                wait(lambda: any(m.twist.linear.z > 0.1 for m in list(twists.msgs)), "the follower back")
                wait(moving, f"joint commands after the {jump} s jump")
                cc_status.clear()
                jog_status.clear()
                wait(lambda: len(cc_status.msgs) > 5 and len(jog_status.msgs) > 5, "both status topics alive")
                assert cc_status.last().move_active, cc_status.last().message
            assert "Traceback" not in h.output(), h.output()[-3000:]
    finally:
        cell.stop()
        for c in (twists, commands, cc_status, jog_status):
            c.close()
        rospy.delete_param("/use_sim_time")
