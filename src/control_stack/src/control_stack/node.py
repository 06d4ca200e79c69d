"""control_stack_node: contact_control and jog_arm as one `CompliantPipeline` in one process.

rospy has no nodelets, so each node hop costs a serialisation, a socket and a deserialisation (about
150 us here). Here a wrench becomes a joint command in one call, with frames from the robot model at the
last joint state (no /tf to deserialise). Everything else keeps the separate nodes' names: parameters under
/contact_control_node and /jog_arm_server (relative to the process's namespace), their private topics and
services there, the same public topics. contact_control's twist is still published when an observer
listens (rosbag, rqt_plot); its copy coming back on jog_arm's input topic is recognised and dropped.
"""

from __future__ import annotations

import sys
import threading
from collections.abc import Sequence

import rospy
from compliant_common.ros_master import MasterWatch
from compliant_common.ros_tf_prefix import for_this_node
from compliant_common.ros_ticker import start_ticker
from compliant_common.runtime import tune_runtime
from contact_control.bias_map import BiasMapError
from contact_control.ros_io import ContactControlRos, TfPoses, read_settings
from contact_control.stage import Velocity
from geometry_msgs.msg import TwistStamped, WrenchStamped
from jog_arm.kinematics import KinematicsError
from jog_arm.node import read_settings as read_jog_settings
from jog_arm.ros_io import JogArmRos
from jog_arm.settings import SettingsError
from sensor_msgs.msg import JointState

from control_stack.pipeline import CompliantPipeline, PipelineOutput

__all__ = ["ControlStackNode", "main"]

CONTACT_CONTROL_NS = "contact_control_node"
JOG_ARM_NS = "jog_arm_server"


class ControlStackNode:
    """Topics in, one pipeline call under one lock, topics out; see the module docstring."""

    def __init__(self, pipeline: CompliantPipeline, tf: TfPoses, cc_ns: str, jog_ns: str) -> None:
        self.pipeline = p = pipeline
        self._lock = threading.Lock()
        cc, jog = p.contact.settings, p.jog.settings
        if p.frames_from_outside():
            tf.listen()
        same_topic = rospy.resolve_name(cc.velocity_out_topic) == rospy.resolve_name(jog.cmd_in_topic)
        # jog_arm's side first: contact_control's services (a ~stop) publish through it as soon as they exist.
        self.jog_ros = JogArmRos(p.jog, self._lock, jog_ns)
        self.contact_ros = ContactControlRos(p.contact, self._lock, cc_ns, self._emit, int(same_topic))
        fast = {"queue_size": 1, "tcp_nodelay": True}
        self._twist_sub = rospy.Subscriber(jog.cmd_in_topic, TwistStamped, self._on_twist, **fast)
        self._subs = [
            rospy.Subscriber(jog.joint_topic, JointState, self._on_joints, **fast),
            rospy.Subscriber(cc.ft_in_topic, WrenchStamped, self._on_wrench, **fast),
            self._twist_sub,
        ]
        start_ticker(self._tick, min(1.0 / cc.control_rate, jog.pub_period), "control_stack_ticks")
        rospy.on_shutdown(self._on_shutdown)

    def _publish(self, out: PipelineOutput, t: float) -> None:
        """What a pipeline call produced: the joint command first (lowest latency), then the twist for
        observers, then the work for the next cycle (lock held)."""
        cycle = out.cycle
        self.jog_ros.publish(cycle)
        self.contact_ros.send(out.twist, t)
        self.pipeline.prepare()
        self.contact_ros.after()
        self.jog_ros.log_notes()

    def _emit(self, twist: Velocity, t: float) -> None:
        """A twist a contact_control request produced (a stop's zero): to jog_arm and observers."""
        self._publish(self.pipeline.from_contact(twist, t), t)

    # The time is read under the lock, right before the call: the pipeline checks each reading for a clock
    # jump against the monotonic clock, and a reading that waited for the lock would look like a step back.
    def _on_joints(self, msg: JointState) -> None:
        with self._lock:
            t = rospy.get_time()
            self._publish(self.pipeline.on_joint_state(msg.name, msg.position, t), t)

    def _on_wrench(self, msg: WrenchStamped) -> None:
        f, q = msg.wrench.force, msg.wrench.torque
        wrench = (f.x, f.y, f.z, q.x, q.y, q.z)
        stamp = msg.header.stamp.to_sec() if not msg.header.stamp.is_zero() else None
        payload = self.contact_ros.payload
        if payload.sampling:
            payload.feed(wrench)
        with self._lock:
            t = rospy.get_time()
            frame = self.contact_ros.tf.bare(msg.header.frame_id)
            self._publish(self.pipeline.on_wrench(wrench, frame, stamp, t), t)
            self.contact_ros.send_contact()  # ~contact_wrench, only while somebody listens (named_poses)

    def _on_twist(self, msg: TwistStamped) -> None:
        lin, ang = msg.twist.linear, msg.twist.angular
        frame = self.jog_ros.ensure_frame(msg.header.frame_id)
        with self._lock:
            t = rospy.get_time()
            out = self.pipeline.on_twist((lin.x, lin.y, lin.z, ang.x, ang.y, ang.z), frame,
                                         msg.header.stamp.to_sec(), t)
            self._publish(out, t)

    def _tick(self) -> float:
        publishers = self._twist_sub.get_num_connections()
        with self._lock:
            t = rospy.get_time()
            self.pipeline.on_twist_publishers(publishers)
            self._publish(self.pipeline.tick(t), t)
            return self.pipeline.next_due()

    def master_lost(self, reason: str) -> None:
        rospy.logerr("control_stack: %s: ending the move, stopping the arm until it returns", reason)
        with self._lock:
            t = rospy.get_time()
            self._publish(self.pipeline.master_lost(reason), t)

    def master_back(self) -> None:
        with self._lock:
            self.pipeline.master_back()

    def _on_shutdown(self) -> None:
        self.contact_ros.shutdown()
        self.jog_ros.shutdown()


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of `rosrun control_stack control_stack_node`; 1 if either part refuses to start."""
    rospy.init_node("control_stack", argv=list(sys.argv if argv is None else argv))
    cc_ns, jog_ns = (rospy.resolve_name(name) + "/" for name in (CONTACT_CONTROL_NS, JOG_ARM_NS))
    jog = read_jog_settings(jog_ns)
    settings = read_settings(cc_ns)
    if jog is None or settings is None:
        return 1
    tf = TfPoses(settings.fixed_frame, for_this_node())
    try:
        pipeline = CompliantPipeline(settings, jog[0], jog[1], tf)
    except (SettingsError, KinematicsError) as err:
        rospy.logfatal(f"jog_arm_server refused to start: {err}")
        return 1
    except BiasMapError as err:
        rospy.logfatal(f"contact_control refused to start: {err}")
        return 1
    node = ControlStackNode(pipeline, tf, cc_ns, jog_ns)
    MasterWatch(node.master_lost, node.master_back, params=[cc_ns, jog_ns, "robot_description"])
    tune_runtime(min(1.0 / settings.control_rate, jog[0].pub_period))
    rospy.loginfo(
        "control_stack: contact_control (%s) -> jog_arm (%s) in one process; wrench in %s, joint commands "
        "out on %s",
        cc_ns, jog_ns, rospy.resolve_name(settings.ft_in_topic), rospy.resolve_name(jog[0].cmd_out_topic),
    )
    rospy.spin()
    return 0
