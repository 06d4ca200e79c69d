"""jog_arm's ROS surface around a `JogStage`: the joint command, `~status`, `~pause`/`~resume`/`~cycle_stats`.

Used by jog_arm_server and by control_stack_node (which shares a process with contact_control). Also looks
up, once, in tf the command frames the robot model lacks (cached as fixed relative to `planning_frame`).
"""

from __future__ import annotations

import threading
import time

import pinocchio as pin
import rospy
import tf2_ros
from compliant_common.diagnostics import Report
from compliant_common.ros_diagnostics import DiagnosticsPublisher
from compliant_common.ros_live_params import LiveParams
from compliant_common.ros_tf_prefix import for_this_node
from compliant_common.typedefs import ParamMap
from compliant_control_msgs.msg import JogStatus
from geometry_msgs.msg import Vector3
from std_msgs.msg import Float64MultiArray
from std_srvs.srv import Trigger, TriggerRequest, TriggerResponse
from trajectory_msgs.msg import JointTrajectory, JointTrajectoryPoint

from jog_arm.health import jog_health
from jog_arm.ros_robot_stop import RobotStopRos
from jog_arm.settings import PARAMETERS, TUNABLE, JogSettings, SettingsError
from jog_arm.stage import JogCycle, JogStage, log_level

__all__ = ["JogArmRos", "load"]

_TF_ERRORS = (tf2_ros.LookupException, tf2_ros.ConnectivityException, tf2_ros.ExtrapolationException)
WARN_PERIOD = 2.0  # [s] throttle of repeated warnings of one kind
# [s] ~pause answers at the latest after this (from full speed at the acceleration limits: about 1 s)
PAUSE_WAIT = 2.0


class JogArmRos:
    """Publishers, services and tf of jog_arm; every stage call holds `lock`.

    Args:
        stage: The jog stage.
        lock: The node's lock around the stage.
        private_ns: Prefix of the private names: "~", or "/jog_arm_server/" in control_stack.
    """

    def __init__(self, stage: JogStage, lock: threading.Lock, private_ns: str = "~") -> None:
        s = self._s = stage.settings
        self._stage, self._lock = stage, lock
        self.tf = for_this_node()  # commands' frames carry the robot's tf prefix, the model's lack it
        self._tf_buffer: tf2_ros.Buffer | None = None
        self._tf_listener: tf2_ros.TransformListener | None = None
        self._frames_ready: set[str] = set()
        self._throttled: dict[str, float] = {}
        self.closed = False
        queue = None if s.publish_synchronously else 1  # None: no sender thread, see the README
        self._cmd_msg: JointTrajectory | Float64MultiArray
        if s.command_out_type == "trajectory":
            self._cmd_msg = JointTrajectory(joint_names=stage.joint_names)
            self._cmd_pub = rospy.Publisher(s.cmd_out_topic, JointTrajectory, queue_size=queue,
                                            tcp_nodelay=True)
        else:
            self._cmd_msg = Float64MultiArray()
            self._cmd_pub = rospy.Publisher(s.cmd_out_topic, Float64MultiArray, queue_size=queue,
                                            tcp_nodelay=True)
        self._status_msg = JogStatus()
        self._under = stage.jog.nv < 6
        self._status_pub = rospy.Publisher(private_ns + "status", JogStatus, queue_size=100)
        self._services = [
            rospy.Service(private_ns + "pause", Trigger, self._on_pause),
            rospy.Service(private_ns + "resume", Trigger, self._on_resume),
            rospy.Service(private_ns + "cycle_stats", Trigger, self._on_cycle_stats),
        ]
        self._health_name = rospy.resolve_name(private_ns).rstrip("/")  # jog_arm_server in both layouts
        self._counted: tuple[float, int] | None = None  # (monotonic time, cycles run) at the last report
        self._rate: float | None = None
        self._health = DiagnosticsPublisher(self._health_report, s.planning_frame)
        self._prefix = self._health_name.lstrip("/") + "/"
        self._live = LiveParams(PARAMETERS, TUNABLE, PARAMETERS.values_of(s), self._retune, private_ns)
        self._robot_stop = RobotStopRos(stage, lock, private_ns, self._prefix)
        rospy.loginfo(
            "jog_arm_server: %d joints %s, tip %s, commands on %s (%s) -> %s on %s every %.4f s",
            len(stage.joint_names), stage.joint_names, s.ee_frame_name, rospy.resolve_name(s.cmd_in_topic),
            s.command_in_type, s.command_out_type, rospy.resolve_name(s.cmd_out_topic), s.pub_period,
        )
        if self._under:
            rospy.loginfo("jog_arm_server: fewer than 6 joints: translation first, rotations as far as "
                          "the arm can; the status names the rotations it cannot make (README)")

    # --- out ---
    def publish(self, cycle: JogCycle | None) -> None:
        """The cycle's joint command and status (status only while somebody listens); logs status changes.
        Called with the node's lock held (the messages are shared by its threads)."""
        if cycle is None or self.closed:
            return
        if cycle.publish:
            self._publish_command(cycle)
        if self._status_pub.get_num_connections() > 0:  # nobody listening: save the cycle the work
            msg = self._status_msg
            msg.header.stamp = rospy.Time.from_sec(cycle.t)
            msg.code, msg.code_name, msg.message = int(cycle.status), cycle.status.name, cycle.message
            msg.condition_number, msg.speed_scale = cycle.condition, cycle.scale
            msg.speed_cap, msg.body_region = cycle.speed_cap, self._stage.settings.collaborative_region
            if self._under:  # fewer than six joints: which rotations the twist cannot have (README)
                axes = self._stage.jog.uncontrolled_rotations()
                msg.uncontrolled_rotations = [Vector3(*axis) for axis in axes]
                msg.message += "; " + _uncontrolled_text(axes, self._s.planning_frame)
            self._status_pub.publish(msg)
        if cycle.status_changed:
            level = log_level(cycle.status)
            log = rospy.logdebug if level == "debug" else rospy.loginfo if level == "info" else rospy.logwarn
            log("jog_arm_server: %s: %s", cycle.status.name, cycle.message)

    def _publish_command(self, cycle: JogCycle) -> None:
        msg = self._cmd_msg  # shared by the threads that run cycles: the node's lock is held
        if isinstance(msg, Float64MultiArray):
            msg.data = cycle.velocities
        else:
            # Stamp 0: "start now" for joint_trajectory_controller, whatever the transport delay.
            duration = rospy.Duration.from_sec
            points = [JointTrajectoryPoint(positions=cycle.positions, velocities=cycle.velocities,
                                           time_from_start=duration(self._s.pub_period))]
            points.extend(
                JointTrajectoryPoint(positions=q, velocities=v, time_from_start=duration(t))
                for q, v, t in cycle.ahead
            )
            msg.points = points
        self._cmd_pub.publish(msg)

    def log_notes(self) -> None:
        """Logs the stage's notes (lock held); "warn_throttle" ones at most once per WARN_PERIOD per kind."""
        stage = self._stage
        if not stage.notes:
            return
        now = time.monotonic()
        for level, text in stage.notes:
            if level == "warn_throttle":
                kind = text.split(":", 1)[0]
                if now < self._throttled.get(kind, 0.0):
                    continue
                self._throttled[kind] = now + WARN_PERIOD
            (rospy.logerr if level == "error" else rospy.logwarn)("jog_arm_server: %s", text)
        stage.notes.clear()

    # --- frames ---
    def ensure_frame(self, received: str) -> str:
        """Makes a frame tf knows but the model does not usable (looked up once, then cached) under its bare
        name (`tf.bare`), which it returns ("": the default command frame). Without the lock: the tf lookup
        may wait."""
        bare = self.tf.bare(received)
        frame = bare or self._s.default_cmd_frame
        if frame in self._frames_ready:
            return bare
        with self._lock:
            known = self._stage.knows_frame(frame)
        if known:
            self._frames_ready.add(frame)
            return bare
        if self._tf_buffer is None:
            self._tf_buffer = tf2_ros.Buffer()
            self._tf_listener = tf2_ros.TransformListener(self._tf_buffer)
        try:
            tf = self._tf_buffer.lookup_transform(self.tf.add(self._s.planning_frame),
                                                  received.lstrip("/") or self.tf.add(frame), rospy.Time(0))
        except _TF_ERRORS as err:  # not cached: tf may still be filling up; try again next command
            rospy.logwarn_throttle(
                WARN_PERIOD, f"jog_arm_server: frame {frame!r} is in neither the robot model nor tf: {err}"
            )
            return bare
        q = tf.transform.rotation
        rotation = pin.Quaternion(q.w, q.x, q.y, q.z).normalized().toRotationMatrix()
        with self._lock:
            self._stage.add_frame(frame, self._s.planning_frame, rotation)
        self._frames_ready.add(frame)
        rospy.loginfo("jog_arm_server: commands in %r use its tf rotation to %r, looked up once (assumed "
                      "fixed)", frame, self._s.planning_frame)
        return bare

    # --- services ---
    def _on_pause(self, _req: TriggerRequest) -> TriggerResponse:
        """Pauses and answers once the arm is at rest and the halt commands are out, so that the caller
        (named_poses before a trajectory) can use the driver at once: nothing of jog_arm's follows."""
        with self._lock:
            if self._stage.pause():
                return TriggerResponse(success=True, message="already paused: commands ignored until ~resume")
        start = time.monotonic()
        while not rospy.is_shutdown():
            with self._lock:
                if self._stage.jog.silent:
                    waited = time.monotonic() - start
                    stopped = f" after stopping for {waited:.2f} s" if waited > 0.001 else ""
                    return TriggerResponse(success=True, message=(
                        f"paused: at rest{stopped}, nothing more published; commands ignored until ~resume"))
            if time.monotonic() - start > PAUSE_WAIT:
                break
            time.sleep(0.005)  # the service's own thread polls the cycles; the control loop never waits
        return TriggerResponse(success=True, message=(
            f"paused: still stopping after {PAUSE_WAIT:g} s; commands ignored until ~resume"))

    def _on_resume(self, _req: TriggerRequest) -> TriggerResponse:
        with self._lock:
            return TriggerResponse(success=True, message=self._stage.resume())

    def _on_cycle_stats(self, _req: TriggerRequest) -> TriggerResponse:
        """Cycle timing since the previous call (or start), then starts a new window."""
        with self._lock:
            return TriggerResponse(success=True, message=self._stage.cycle_stats())

    # --- live tuning ---
    def _retune(self, changed: dict[str, object]) -> str:
        """dynamic_reconfigure's change, checked as at start-up and applied under the lock from the next
        cycle; '' or why it is refused (nothing changed then)."""
        with self._lock:
            try:
                settings = self._stage.settings.retuned(changed, self._prefix)
            except SettingsError as err:
                return str(err)
            self._stage.retune(settings)
        return ""

    # --- health ---
    def _health_report(self) -> Report:
        """jog_arm_server's /diagnostics (its own thread, every 0.1 s; jog_arm.health)."""
        with self._lock:  # only the reads
            cycle, cycles, master = self._stage.last_cycle, self._stage.cycles_run, self._stage.suspended
            stopped = self._stage.robot_stop
        now = time.monotonic()
        if self._counted is None or now - self._counted[0] >= 0.5:  # a new window
            if self._counted is not None:
                self._rate = (cycles - self._counted[1]) / (now - self._counted[0])
            self._counted = (now, cycles)
        return jog_health(self._health_name, cycle, self._rate, 1.0 / self._s.pub_period, master,
                          self._stage.settings.collaborative_region, stopped)

    def master_lost(self, reason: str) -> None:
        rospy.logerr("jog_arm_server: %s: stopping the arm until it returns", reason)

    def shutdown(self) -> None:
        """Stops publishing and unregisters the services and publishers."""
        self.closed = True
        self._health.close()
        self._robot_stop.shutdown()
        for service in self._services:
            service.shutdown()
        self._cmd_pub.unregister()
        self._status_pub.unregister()


def load(params: ParamMap, urdf_xml: str | None, prefix: str) -> tuple[JogSettings, list[str]]:
    """Validates the parameters and the presence of a robot description (no ROS calls).

    Raises:
        SettingsError: Naming the bad key, or the missing robot_description.
    """
    settings, warnings = JogSettings.from_params_with_warnings(params, prefix)
    if not urdf_xml:
        raise SettingsError("robot_description parameter is missing or empty: load the URDF first")
    return settings, warnings


def _uncontrolled_text(axes: list[tuple[float, float, float]], frame: str) -> str:
    """'cannot turn about [+0.00 +1.00 +0.00] of base_link (5 joints: translation first)'."""
    named = " or ".join("[" + " ".join(f"{c:+.2f}" for c in axis) + "]" for axis in axes)
    return f"cannot turn about {named} of {frame} (fewer than 6 joints: translation first)" if axes else \
        "fewer than 6 joints: translation first"
