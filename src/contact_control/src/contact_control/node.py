"""contact_control_node: the rospy adapter around a `ContactStage` (see the package README).

Per wrench: one `ContactStage.on_wrench` (frames from tf, static ones cached) and the twist published at
once (lowest latency); the contact force for jog_arm's guard after it, off that path. One thread wakes when
the newest wrench turns stale and then every 1/control_rate while a move waits for data. Services, status
and publishers: `ros_io.ContactControlRos`.
"""

from __future__ import annotations

import sys
import threading
from collections.abc import Sequence

import rospy
from compliant_common.clock import ClockJump
from compliant_common.ros_master import MasterWatch
from compliant_common.ros_tf_prefix import for_this_node
from compliant_common.ros_ticker import start_ticker
from compliant_common.ros_time import JumpAwareClock
from compliant_common.runtime import tune_runtime
from geometry_msgs.msg import WrenchStamped
from sensor_msgs.msg import JointState

from contact_control.bias_map import BiasMapError
from contact_control.params import PARAMETERS, ContactControlSettings
from contact_control.ros_io import ContactControlRos, TfPoses, fill_status_words, read_settings
from contact_control.stage import ContactStage, describe_laws

__all__ = ["ContactControlNode", "describe_laws", "fill_status_words", "main", "read_settings"]


class ContactControlNode:
    """A wrench subscriber and a stale-data thread around one `ContactStage`; every call holds `_lock`."""

    def __init__(self, settings: ContactControlSettings) -> None:
        s = settings
        self._lock = threading.Lock()
        self._clock = JumpAwareClock()
        tf = TfPoses(s.fixed_frame, for_this_node())
        self.stage = ContactStage(settings, tf)
        if self.stage.frames_used:
            tf.listen()
        self.ros = ContactControlRos(self.stage, self._lock)
        self._sub = rospy.Subscriber(s.ft_in_topic, WrenchStamped, self._on_wrench, queue_size=1,
                                     tcp_nodelay=True)
        if self.stage.bias_map is not None:  # its offset follows the joints
            self._joints_sub = rospy.Subscriber(s.bias_map_joint_states, JointState, self._on_joint_state,
                                                queue_size=1, tcp_nodelay=True)
        start_ticker(self._tick, 1.0 / s.control_rate, "contact_control_ticks")
        rospy.on_shutdown(self.ros.shutdown)

    def _on_wrench(self, msg: WrenchStamped) -> None:
        t, jump = self._clock.read()
        if jump is not None:
            self._on_clock_jump(jump, t)
            return
        f, q = msg.wrench.force, msg.wrench.torque
        wrench = (f.x, f.y, f.z, q.x, q.y, q.z)
        stamp = msg.header.stamp.to_sec() if not msg.header.stamp.is_zero() else None
        if self.ros.payload.sampling:
            self.ros.payload.feed(wrench)
        with self._lock:
            self.ros.send(self.stage.on_wrench(wrench, self.ros.tf.bare(msg.header.frame_id), stamp, t), t)
            self.stage.update_contact()  # after the twist: off its path
            self.ros.send_contact()
            self.ros.after()

    def _on_joint_state(self, msg: JointState) -> None:
        with self._lock:
            self.stage.on_joint_state(msg.name, msg.position)

    def _tick(self) -> float:
        t, jump = self._clock.read()
        if jump is not None:
            self._on_clock_jump(jump, t)
        with self._lock:
            if t >= self.stage.next_due():
                self.ros.emit_locked(self.stage.tick(t), t)
            return self.stage.next_due()

    def _on_clock_jump(self, jump: ClockJump, t: float) -> None:
        """Halts and restarts the timing; the move resumes with the next wrench stamped after the jump."""
        with self._lock:
            self.ros.emit_locked(self.stage.clock_jumped(jump.describe(), t), t)


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of `rosrun contact_control contact_control_node`."""
    rospy.init_node("contact_control_node", argv=list(sys.argv if argv is None else argv))
    settings = read_settings()
    if settings is None:
        return 1
    try:
        node = ContactControlNode(settings)
    except BiasMapError as err:
        rospy.logfatal("contact_control_node: not starting: %s", err)
        return 1
    MasterWatch(node.ros.master_lost, node.ros.master_back, params=["~"])
    tune_runtime(1.0 / settings.control_rate)
    rospy.loginfo(
        "contact_control_node: wrench in %s, twist out %s (%s), control frame %s, %d parameters loaded",
        rospy.resolve_name(settings.ft_in_topic), rospy.resolve_name(settings.velocity_out_topic),
        settings.velocity_command_frame, settings.control_frame, len(PARAMETERS),
    )
    rospy.spin()
    return 0
