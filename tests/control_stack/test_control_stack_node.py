"""control_stack_node: contact_control and jog_arm in one process, under the separate nodes' names.

A UR5 at a fixed joint state, wrenches in, a follower on Z: every twist contact_control publishes is turned
into exactly one joint command (the copy of the twist coming back over the topic is dropped), the command
moves the tool along the push, and both parts' services answer under their usual names.
"""

from __future__ import annotations

import pathlib
import sys

import numpy as np
import pytest

pytest.importorskip("cartesian_impedance_msgs.srv", reason="needs devel/setup.bash (make test sources it)")

from cartesian_impedance_msgs.srv import ConfigureForceControl, ConfigureForceControlRequest
from geometry_msgs.msg import TwistStamped, WrenchStamped
from harness.launch import run_node
from harness.streams import Repeater
from harness.waiting import Collector, wait_until
from sensor_msgs.msg import JointState
from std_msgs.msg import Float64MultiArray
from std_srvs.srv import Trigger

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parents[1] / "jog_arm"))
from jog_arm_testing import UR5

from jog_arm import ArmModel

NS = "/cs_test"
TWIST, COMMAND = f"{NS}/jog_arm_server/delta_jog_cmds", f"{NS}/command"
JOG = {  # jog_arm's input is contact_control's output topic, as in the robot packages
    "ee_frame_name": UR5.tip, "planning_frame": "base_link", "command_in_type": "speed_units",
    "joint_topic": "joint_states", "cmd_in_topic": "jog_arm_server/delta_jog_cmds",
    "cmd_out_topic": "command",
    "command_out_type": "velocity_array", "integrate_from": "measured", "publish_on_command": True,
    "pub_period": 1.0,  # the timer alone: one command per second; twists drive every other command
    "incoming_cmd_timeout": 5.0,
}
CONTACT = {
    "ft_in_topic": "wrench", "velocity_out_topic": "jog_arm_server/delta_jog_cmds", "tare_on_startup": False,
    "lp_filter_enabled": False, "eef_frame": "base_link",
    # Never stale during the test: stale data makes the timer publish zero twists at 500 Hz, and jog_arm (by
    # design) answers only the first few zeros with commands, so the counts below would not compare.
    "wrench_timeout": 30.0, "no_data_end_timeout": 60.0,
}


def test_one_joint_command_per_twist_in_the_push_direction_with_the_usual_service_names(ros_node):
    rospy = ros_node
    rospy.set_param(f"{NS}/robot_description", UR5.urdf)
    rospy.set_param(f"{NS}/jog_arm_server", JOG)
    rospy.set_param(f"{NS}/contact_control_node", CONTACT)
    model = ArmModel(UR5.urdf, UR5.tip)
    joints = rospy.Publisher(f"{NS}/joint_states", JointState, queue_size=1, latch=True)
    driver = Repeater(joints).start(JointState(name=list(model.joint_names), position=list(UR5.start)), 100.0)
    wrench = rospy.Publisher(f"{NS}/wrench", WrenchStamped, queue_size=10, tcp_nodelay=True)
    twists, commands = Collector(TWIST, TwistStamped), Collector(COMMAND, Float64MultiArray)
    try:
        with run_node("control_stack", "control_stack_node", args=[f"__ns:={NS}"]) as h:
            for service in ("configure_cartesian_impedance", "configure_laws", "contact_control_node/stop",
                            "jog_arm_server/pause", "jog_arm_server/cycle_stats"):
                h.wait_for_service(f"{NS}/{service}", timeout=30)
            wait_until(lambda: wrench.get_num_connections() > 0, 20, "the stack to subscribe to the wrench")
            twists.wait_connected()  # the twist publisher starts last: count from its first twist
            commands.wait_connected()
            req = ConfigureForceControlRequest()
            req.direction_control_laws.z.type = 1  # follower, b = 50: 10 N -> 0.2 m/s, capped at max_velocity
            req.cart_impedance_params.damping.translational.z = 50.0
            configure = rospy.ServiceProxy(f"{NS}/configure_cartesian_impedance", ConfigureForceControl)
            assert configure(req).success, h.output()[-2000:]

            msg = WrenchStamped()
            msg.header.frame_id = "base_link"
            msg.wrench.force.z = 10.0
            rate = rospy.Rate(100)
            twists.clear()
            commands.clear()
            for _ in range(100):  # 1 s of pushing up
                msg.header.stamp = rospy.Time.now()
                wrench.publish(msg)
                rate.sleep()  # the sensor's rate, not a wait for a result
            # Only the motion counts: zero twists before the first wrench (a move waiting for data) and
            # jog_arm's halt commands come and go with timing, not one per twist.
            def moving_counts() -> tuple[int, int]:
                up = sum(1 for m in list(twists.msgs) if m.twist.linear.z > 0.0)
                return up, sum(1 for m in list(commands.msgs) if any(m.data))

            wait_until(lambda: moving_counts()[1] >= moving_counts()[0] - 2, 5, "commands for the twists")
            n_twists, n_commands = moving_counts()
            assert n_twists >= 50, h.output()[-2000:]
            # One command per twist, give or take a timer cycle: a twist handled twice would double it.
            assert n_twists - 2 <= n_commands <= n_twists + 2, (n_twists, n_commands)
            v = model.jacobian(np.asarray(UR5.start)) @ np.asarray(commands.last().data)
            assert v[2] > 0.01 and abs(v[0]) < 0.1 * v[2] and abs(v[1]) < 0.1 * v[2], v
            assert rospy.ServiceProxy(f"{NS}/contact_control_node/stop", Trigger)().success
    finally:
        for c in (twists, commands):
            c.close()
        driver.stop()
        joints.unregister()
        wrench.unregister()
