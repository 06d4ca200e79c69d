"""jog_arm_server: the rospy adapter around a `JogStage` (see the package README).

Callbacks hand data to the stage under one lock and publish what it returns (`ros_io.JogArmRos`); one thread
runs the cycles that are due by time (every `pub_period`, or gap fills with `publish_on_command`). Frames a
command names that the robot model lacks are looked up once in tf.
"""

from __future__ import annotations

import sys
import threading

import rospy
from compliant_common.ros_master import MasterWatch
from compliant_common.ros_ticker import start_ticker
from compliant_common.ros_time import JumpAwareClock
from compliant_common.runtime import tune_runtime
from geometry_msgs.msg import TwistStamped, WrenchStamped
from sensor_msgs.msg import JointState

from jog_arm.kinematics import KinematicsError
from jog_arm.ros_io import JogArmRos, load
from jog_arm.settings import JogSettings, SettingsError
from jog_arm.stage import JogStage

__all__ = ["JogArmNode", "load", "main", "read_settings"]


class JogArmNode:
    """Subscribers and the cycle thread around one `JogStage`; every stage call holds `_lock`.

    Raises:
        KinematicsError, SettingsError: The configuration does not fit the robot model.
    """

    def __init__(self, settings: JogSettings, urdf_xml: str) -> None:
        self._lock = threading.Lock()
        self.stage = JogStage(settings, urdf_xml)
        self.ros = JogArmRos(self.stage, self._lock)
        # A clock that stops (a dead /clock source) is a fault too: commands would never turn stale.
        self._clock = JumpAwareClock(stop_tolerance=max(0.5, 2.0 * settings.incoming_cmd_timeout))
        fast: dict[str, object] = {"queue_size": 1, "tcp_nodelay": True}
        self._subs = [
            rospy.Subscriber(settings.joint_topic, JointState, self._on_joints, **fast),
            rospy.Subscriber(settings.cmd_in_topic, TwistStamped, self._on_twist, **fast),
            # contact_control's laws (two-node layout): an input of their own, not through the guard.
            rospy.Subscriber(settings.contact_cmd_in_topic, TwistStamped, self._on_contact_twist, **fast),
        ]
        if settings.contact_guard_enabled:  # the force from contact_control_node's ~contact_wrench
            self._subs.append(rospy.Subscriber(settings.contact_guard_wrench_topic, WrenchStamped,
                                               self._on_contact_wrench, **fast))
        start_ticker(self._tick, settings.pub_period, "jog_arm_cycles")

    def _now(self) -> float:
        """The ROS time [s]; a jump (or a stopped clock) is handed to the stage first (lock held)."""
        now, jump = self._clock.read()
        if jump is not None:
            self.stage.clock_jumped(jump.describe())
        return now

    def _on_joints(self, msg: JointState) -> None:
        with self._lock:
            self.stage.on_joint_state(msg.name, msg.position, self._now())
            self.ros.log_notes()

    def _on_contact_wrench(self, msg: WrenchStamped) -> None:
        f = msg.wrench.force
        with self._lock:
            self.stage.on_contact_wrench((f.x, f.y, f.z), self.ros.tf.bare(msg.header.frame_id), self._now())

    def _on_twist(self, msg: TwistStamped) -> None:
        """An outside twist (keyboard, GUI, rostopic pub): through the contact guard."""
        self._twist(msg, guarded=True)

    def _on_contact_twist(self, msg: TwistStamped) -> None:
        """contact_control's twist: its laws react to the force themselves."""
        self._twist(msg, guarded=False)

    def _twist(self, msg: TwistStamped, guarded: bool) -> None:
        lin, ang = msg.twist.linear, msg.twist.angular
        frame = self.ros.ensure_frame(msg.header.frame_id)
        with self._lock:
            cycle = self.stage.on_twist((lin.x, lin.y, lin.z, ang.x, ang.y, ang.z), frame,
                                        self._now(), guarded=guarded)
            self.ros.publish(cycle)
            self.ros.log_notes()
            if cycle is not None and cycle.publish:
                self.stage.prepare()  # the next cycle's Jacobian, off the twist-to-command path

    def _tick(self) -> float:
        publishers = self._subs[1].get_num_connections()
        with self._lock:
            t = self._now()
            self.stage.on_publishers(publishers)
            cycle = self.stage.tick(t)
            self.ros.publish(cycle)
            self.ros.log_notes()
            if cycle is not None and cycle.publish:
                self.stage.prepare()
            return self.stage.next_due()

    def on_master_lost(self, reason: str) -> None:
        """The graph is broken: stop, and refuse commands until the master is back."""
        self.ros.master_lost(reason)
        with self._lock:
            self.stage.suspend(reason)

    def on_master_back(self) -> None:
        with self._lock:
            self.stage.unsuspend()

    def shutdown(self) -> None:
        """Stops publishing and unregisters topics and services."""
        self.ros.shutdown()
        for sub in self._subs:
            sub.unregister()


def read_settings(param_ns: str = "~") -> tuple[JogSettings, str] | None:
    """Settings and robot description from the parameter server (after rospy.init_node); None, with a fatal
    log naming the key, if they are refused."""
    prefix = rospy.get_name() + "/" if param_ns == "~" else param_ns.rstrip("/") + "/"
    try:
        urdf = rospy.get_param("robot_description", None)
        settings, warnings = load(rospy.get_param(param_ns, {}), urdf, prefix)
    except SettingsError as err:
        rospy.logfatal(f"jog_arm_server refused to start: {err}")
        return None
    for warning in warnings:
        rospy.logwarn(warning)
    return settings, urdf


def main(argv: list[str] | None = None) -> int:
    """Runs the node until shutdown. Returns 1, with a fatal log naming the key, if start-up is refused."""
    rospy.init_node("jog_arm_server", argv=argv)
    loaded = read_settings()
    if loaded is None:
        return 1
    try:
        node = JogArmNode(*loaded)
    except (SettingsError, KinematicsError) as err:
        rospy.logfatal(f"jog_arm_server refused to start: {err}")
        return 1
    rospy.on_shutdown(node.shutdown)
    MasterWatch(node.on_master_lost, node.on_master_back, params=["~", "robot_description"])
    tune_runtime(node.stage.settings.pub_period)
    rospy.spin()
    return 0


if __name__ == "__main__":
    sys.exit(main())
