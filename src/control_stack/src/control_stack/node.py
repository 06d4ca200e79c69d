"""control_stack_node: contact_control_node and jog_arm_server sharing one process.

rospy has no nodelets, so each node hop costs a serialisation, a socket and a deserialisation (about
150 us here). In one process contact_control calls jog_arm with each twist directly and takes its frames
from jog_arm's robot model at the last joint state (no /tf to deserialise). Everything else keeps the
separate nodes' names: parameters under /contact_control_node and /jog_arm_server (relative to the
process's namespace), their private topics and services there, the same public topics. The twist is
still published when an observer listens (rosbag, rqt_plot); jog_arm drops the copy coming back from
this process, so every twist is handled once.
"""

from __future__ import annotations

import sys
from collections.abc import Sequence

import rospy
from compliant_common.master import MasterWatch
from compliant_common.runtime import tune_runtime
from contact_control.node import ContactControlNode, read_settings
from jog_arm.node import start as start_jog_arm

__all__ = ["main"]

CONTACT_CONTROL_NS = "contact_control_node"
JOG_ARM_NS = "jog_arm_server"


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of `rosrun control_stack control_stack_node`; 1 if either part refuses to start."""
    rospy.init_node("control_stack", argv=list(sys.argv if argv is None else argv))
    cc_ns, jog_ns = (rospy.resolve_name(name) + "/" for name in (CONTACT_CONTROL_NS, JOG_ARM_NS))
    jog = start_jog_arm(param_ns=jog_ns, private_ns=jog_ns, skip_callerid=rospy.get_name())
    settings = read_settings(cc_ns)
    if jog is None or settings is None:
        return 1
    twist_topic = rospy.resolve_name(settings.velocity_out_topic)
    same_topic = twist_topic == rospy.resolve_name(jog.settings.cmd_in_topic)
    contact = ContactControlNode(
        settings,
        private_ns=cc_ns,
        twist_sink=jog.accept_velocity,
        frame_source=jog.model_frame_pose,
        own_subscribers=int(same_topic),
    )
    # jog_arm's contact guard on outside twists reads contact_control's compensated force in-process.
    jog.use_contact_source(contact.contact_force)

    def on_lost(reason: str) -> None:
        contact.on_master_lost(reason)
        jog.on_master_lost(reason)

    def on_back() -> None:
        contact.on_master_back()
        jog.on_master_back()

    MasterWatch(on_lost, on_back, params=[cc_ns, jog_ns, "robot_description"])
    tune_runtime(min(1.0 / settings.control_rate, jog.settings.pub_period))
    rospy.loginfo(
        "control_stack: contact_control (%s) -> jog_arm (%s) in one process; wrench in %s, joint commands "
        "out on %s",
        cc_ns,
        jog_ns,
        rospy.resolve_name(settings.ft_in_topic),
        rospy.resolve_name(jog.settings.cmd_out_topic),
    )
    rospy.spin()
    return 0
