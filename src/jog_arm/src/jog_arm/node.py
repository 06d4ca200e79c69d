"""jog_arm_server: the rospy adapter around :class:`jog_arm.JogCalcs` (see the package README).

Callbacks only hand data to the library under a lock; a timer at ``pub_period`` runs one cycle and
publishes the joint command (JointTrajectory or Float64MultiArray) and ``~status``. Frames a command names
that the robot model lacks are looked up once in tf (relative to ``planning_frame``) and cached as fixed
frames; frames tf does not have either are refused with a warning.
"""

from __future__ import annotations

import math
import sys
import threading
import time
from collections.abc import Callable, Sequence
from typing import Any

import pinocchio as pin
import rospy
import tf2_ros
from compliant_common.clock import ClockJump
from compliant_common.master import MasterWatch
from compliant_common.ros_time import JumpAwareClock, timer
from compliant_common.runtime import tune_runtime
from compliant_control_msgs.msg import JogStatus
from geometry_msgs.msg import TwistStamped, WrenchStamped
from sensor_msgs.msg import JointState
from std_msgs.msg import Float64MultiArray
from std_srvs.srv import Trigger, TriggerResponse
from trajectory_msgs.msg import JointTrajectory, JointTrajectoryPoint

from jog_arm.contact_guard import ContactGuard
from jog_arm.jog_calcs import JogCalcs
from jog_arm.kinematics import KinematicsError
from jog_arm.settings import JogSettings, SettingsError
from jog_arm.status import StatusCode
from jog_arm.timing import CycleMonitor, next_fill_time

__all__ = ["ContactSource", "JogArmNode", "main", "start"]

#: Returns the latest contact force on the tool: ((fx, fy, fz) [N], its frame, the time it was measured [s]),
#: or None when there is none yet.
ContactSource = Callable[[], "tuple[Sequence[float], str, float] | None"]

_TF_ERRORS = (tf2_ros.LookupException, tf2_ros.ConnectivityException, tf2_ros.ExtrapolationException)
_WARN_PERIOD = 2.0  # [s] throttle of repeated warnings
NOTE_SHOWN_FOR = 1.0  # [s] a clock jump stays on ~status at least this long
# While the contact guard cuts an outside twist, ~status says so instead of these (it is why the arm stops).
_GUARD_OUTRANKS = (StatusCode.NO_WARNING, StatusCode.JOINT_VELOCITY_SCALED, StatusCode.STALE_COMMAND)


class JogArmNode:
    """Topics, services, tf and the timer around one `JogCalcs`; every call into it holds `_lock`.

    Args:
        settings: Validated parameters.
        urdf_xml: The robot description.
        private_ns: Prefix of the private topics and services: "~" in a node of its own,
            "/jog_arm_server/" when sharing a process (control_stack).
        skip_callerid: Twists from this publisher (the process itself) arrive through `accept_velocity`,
            so their copies on the topic are dropped.

    Raises:
        KinematicsError, SettingsError: The configuration does not fit the robot model.
    """

    def __init__(
        self, settings: JogSettings, urdf_xml: str, private_ns: str = "~", skip_callerid: str | None = None
    ) -> None:
        self._s = settings
        self._jog = JogCalcs(settings, urdf_xml)
        self._lock = threading.Lock()
        self._pub_lock = threading.Lock()
        # tf only for command frames the model lacks: created on the first such frame, so the usual case
        # spends no thread on deserialising /tf.
        self._tf_buffer: tf2_ros.Buffer | None = None
        self._tf_listener: tf2_ros.TransformListener | None = None
        self._frames_ready: set[str] = set()  # command frames known to be usable (model, or tf looked up)
        self._last_status = StatusCode.NO_JOINT_STATE
        self._last_twist_cycle = -math.inf
        self._last_fill = -math.inf
        # A clock that stops (a dead /clock source) is a fault too: commands would never turn stale.
        self._clock = JumpAwareClock(stop_tolerance=max(0.5, 2.0 * settings.incoming_cmd_timeout))
        self._from_topic = False  # whether the current command came over the topic (not in-process)
        self._publishers = 0  # connections of the twist subscriber at the last cycle
        self._fault_note = ""  # a clock jump, shown on ~status for NOTE_SHOWN_FOR s
        self._fault_shown_until = 0.0
        self._cycles = CycleMonitor(settings.pub_period)
        self._next_missed_warning = -math.inf
        names = list(self._jog.joint_names)
        self._joint_set = frozenset(names)
        self._points = settings.simu_points if settings.simu else 1
        queue = None if settings.publish_synchronously else 1  # None: no sender thread, see the README
        if settings.command_out_type == "trajectory":
            self._cmd_msg: Any = JointTrajectory(joint_names=names)
            self._cmd_pub = rospy.Publisher(
                settings.cmd_out_topic, JointTrajectory, queue_size=queue, tcp_nodelay=True
            )
        else:
            self._cmd_msg = Float64MultiArray()
            self._cmd_pub = rospy.Publisher(
                settings.cmd_out_topic, Float64MultiArray, queue_size=queue, tcp_nodelay=True
            )
        self._status_msg = JogStatus()
        self._status_pub = rospy.Publisher(private_ns + "status", JogStatus, queue_size=100)
        self._services = [
            rospy.Service(private_ns + "pause", Trigger, self._on_pause),
            rospy.Service(private_ns + "resume", Trigger, self._on_resume),
            rospy.Service(private_ns + "cycle_stats", Trigger, self._on_cycle_stats),
        ]
        self._skip_callerid = skip_callerid
        fast = {"queue_size": 1, "tcp_nodelay": True}
        self._subs = [
            rospy.Subscriber(settings.joint_topic, JointState, self._on_joints, **fast),
            rospy.Subscriber(settings.cmd_in_topic, TwistStamped, self._on_twist, **fast),
        ]
        # Contact-force guard on outside twists: the force comes from a topic (two nodes) until a controller
        # in the same process provides it (`use_contact_source`, control_stack).
        self._guard: ContactGuard | None = None
        self._contact: tuple[Sequence[float], str, float] | None = None
        self._contact_source: ContactSource = lambda: self._contact
        self._guard_note = ""
        self._guard_code = False  # the guard acted on the current command
        self._guard_sub: rospy.Subscriber | None = None
        if settings.contact_guard_enabled:
            self._guard = ContactGuard(
                settings.contact_guard_max_force,
                settings.contact_guard_slow_force,
                settings.contact_guard_slow_speed,
                settings.contact_guard_timeout,
                settings.contact_guard_relief_speed,
            )
            self._guard_sub = rospy.Subscriber(
                settings.contact_guard_wrench_topic, WrenchStamped, self._on_contact_wrench, **fast
            )
        self._closed = False
        if settings.publish_on_command:  # twists run the cycles; a timer would wake 1/pub_period times a s
            self._timer: rospy.Timer | None = None
            threading.Thread(target=self._fill_gaps, name="jog_arm_gap_filler", daemon=True).start()
        else:
            self._timer = timer(settings.pub_period, self._on_timer)
        rospy.loginfo(
            "jog_arm_server: %d joints %s, tip %s, commands on %s (%s) -> %s on %s every %.4f s",
            len(names),
            names,
            settings.ee_frame_name,
            rospy.resolve_name(settings.cmd_in_topic),
            settings.command_in_type,
            settings.command_out_type,
            rospy.resolve_name(settings.cmd_out_topic),
            settings.pub_period,
        )

    # --- callbacks ----------------------------------------------------------------------------------------

    def _on_joints(self, msg: JointState) -> None:
        now = self._now()
        with self._lock:
            ok = self._jog.set_joint_state_named(msg.name, msg.position, now)
        if not ok and self._joint_set.intersection(msg.name):  # other robots' / grippers' states: ignore
            rospy.logwarn_throttle(
                _WARN_PERIOD,
                "jog_arm_server: ignoring a joint state that lacks finite positions for "
                f"{list(self._jog.joint_names)}",
            )

    def _on_twist(self, msg: TwistStamped) -> None:
        header = getattr(msg, "_connection_header", None)
        if self._skip_callerid is not None and header and header.get("callerid") == self._skip_callerid:
            return  # already handed over in-process
        self.accept_twist(msg)

    def accept_twist(self, msg: TwistStamped) -> None:
        """A velocity command from the topic (an outside source: it goes through the contact guard)."""
        lin, ang = msg.twist.linear, msg.twist.angular
        twist: Sequence[float] = (lin.x, lin.y, lin.z, ang.x, ang.y, ang.z)
        now = self._now()
        if self._guard is not None:
            twist = self._guarded(twist, msg.header.frame_id.lstrip("/") or self._s.default_cmd_frame, now)
        self.accept_velocity(twist, msg.header.frame_id, now, from_topic=True)

    # --- contact-force guard ---
    def use_contact_source(self, source: ContactSource) -> None:
        """Takes the contact force from a controller in this process instead of the topic (control_stack)."""
        self._contact_source = source
        if self._guard_sub is not None:
            self._guard_sub.unregister()
            self._guard_sub = None

    def _on_contact_wrench(self, msg: WrenchStamped) -> None:
        f = msg.wrench.force
        self._contact = ((f.x, f.y, f.z), msg.header.frame_id.lstrip("/"), self._now())

    def _guarded(self, twist: Sequence[float], frame: str, now: float) -> Sequence[float]:
        """The twist the contact guard lets through; remembers why for ~status and logs changes."""
        assert self._guard is not None
        contact = self._contact_source()
        force, age = None, 0.0
        if contact is not None:
            raw, force_frame, measured = contact
            age = now - measured
            force = tuple(raw)
            if force_frame and force_frame != frame:
                pose = self.model_frame_pose_or_none(force_frame, frame)
                if pose is None:  # cannot say which way is into the contact: treat like no fresh force
                    force, age = (math.nan,) * 3, 0.0
                else:
                    force = tuple(sum(pose[r][c] * raw[c] for c in range(3)) for r in range(3))
        result = self._guard.limit(twist, force, age)
        if result.message != self._guard_note and result.acted:
            rospy.logwarn_throttle(_WARN_PERIOD, f"jog_arm_server: {result.message}")
        self._guard_note, self._guard_code = result.message, result.acted
        return result.twist

    def model_frame_pose_or_none(self, frame: str, relative_to: str) -> list[list[float]] | None:
        """`model_frame_pose`, or None also before the first joint state."""
        try:
            return self.model_frame_pose(frame, relative_to)
        except LookupError:
            return None

    def accept_velocity(
        self, twist: Sequence[float], frame: str, now: float, from_topic: bool = False
    ) -> None:
        """A velocity command (vx, vy, vz, wx, wy, wz) in `frame` ("": the default) received at `now` [s]:
        from the topic, or from a controller in the same process (no message to fill and read back)."""
        frame = frame.lstrip("/")
        self._ensure_frame(frame or self._s.default_cmd_frame)
        with self._lock:
            result = self._jog.set_command(twist, frame, now)
            self._from_topic = from_topic
        if not result.accepted:
            rospy.logwarn_throttle(_WARN_PERIOD, f"jog_arm_server: command refused: {result.reason}")
        elif self._s.publish_on_command:
            self._last_twist_cycle = now
            self._cycle(now)

    def _ensure_frame(self, frame: str) -> None:
        """Makes a frame tf knows but the model does not usable (looked up once, then cached)."""
        if frame in self._frames_ready:
            return
        with self._lock:
            known = self._jog.has_frame(frame)
        if known:
            self._frames_ready.add(frame)
            return
        if self._tf_buffer is None:
            self._tf_buffer = tf2_ros.Buffer()
            self._tf_listener = tf2_ros.TransformListener(self._tf_buffer)
        try:
            tf = self._tf_buffer.lookup_transform(self._s.planning_frame, frame, rospy.Time(0))
        except _TF_ERRORS as err:  # not cached: tf may still be filling up; try again next command
            rospy.logwarn_throttle(
                _WARN_PERIOD, f"jog_arm_server: frame {frame!r} is in neither the robot model nor tf: {err}"
            )
            return
        q = tf.transform.rotation
        rotation = pin.Quaternion(q.w, q.x, q.y, q.z).normalized().toRotationMatrix()
        with self._lock:
            self._jog.add_frame(frame, self._s.planning_frame, rotation)
        self._frames_ready.add(frame)
        rospy.loginfo(
            "jog_arm_server: commands in %r use its tf rotation to %r, looked up once (assumed fixed)",
            frame,
            self._s.planning_frame,
        )

    def _now(self) -> float:
        """The ROS time [s]; a jump (or a stopped clock) is handled first: see `_on_clock_jump`."""
        now, jump = self._clock.read()
        if jump is not None:
            self._on_clock_jump(jump)
        return now

    def _on_clock_jump(self, jump: ClockJump) -> None:
        note = jump.describe()
        rospy.logwarn("jog_arm_server: %s: stopping until a fresh joint state and a new command", note)
        self._last_twist_cycle = self._last_fill = -math.inf  # the gap filler's schedule was in the old time
        self._fault_note, self._fault_shown_until = note, time.monotonic() + NOTE_SHOWN_FOR
        with self._lock:
            self._jog.clock_jumped(note)

    def _on_timer(self, _event: rospy.timer.TimerEvent) -> None:
        self._cycle(self._now())

    def _fill_gaps(self) -> None:
        """publish_on_command: sleeps while twists run the cycles; runs one when a twist is missing and one
        per period once twists stop (see timing.FILL_AFTER). It sleeps on the wall clock, so neither a clock
        jump nor a stopped clock can stall it."""
        period = self._s.pub_period
        while not (self._closed or rospy.is_shutdown()):
            now = self._now()
            due = next_fill_time(self._last_twist_cycle, self._last_fill, period)
            if now >= due:
                self._last_fill = now
                self._cycle(now)
                due = next_fill_time(self._last_twist_cycle, self._last_fill, period)
            time.sleep(min(max(due - now, 1e-4), period))

    def _cycle(self, now: float) -> None:
        """One control cycle: compute, publish the joint command and the status."""
        if self._closed:  # shutting down: a last twist from contact_control in this process comes too late
            return
        # Throttled here: rospy's logwarn_throttle inspects the caller's source file (~100 us) on every call.
        if self._cycles.tick(now) and now >= self._next_missed_warning:
            self._next_missed_warning = now + 10.0
            rospy.logwarn(
                f"jog_arm_server: {self._cycles.missed} publish cycles missed so far "
                f"(longest gap {self._cycles.max_gap * 1e3:.1f} ms, period {self._s.pub_period * 1e3:g} ms)"
            )
        publishers = self._subs[1].get_num_connections()
        with self._lock:
            if publishers < self._publishers and self._from_topic:  # its publisher died or was stopped
                self._jog.drop_command("the command's publisher disconnected")
                self._from_topic = False
            self._publishers = publishers
            out = self._jog.step(now)
            publish = out.publish
            if publish:
                if self._points > 1:
                    points = self._jog.trajectory_points(self._points)
                else:
                    points = [(out.positions, out.velocities, self._s.pub_period)]
            status, message = out.status, out.message
            condition, scale = out.condition_number, out.speed_scale
            if self._guard_code and self._from_topic and status in _GUARD_OUTRANKS:
                status, message = StatusCode.CONTACT_GUARD, self._guard_note
        if publish:
            self._publish_command(points)
        if self._status_pub.get_num_connections() > 0:  # nobody listening: save the cycle the work
            msg = self._status_msg
            msg.header.stamp = rospy.Time.from_sec(now)
            if self._fault_note:
                if time.monotonic() < self._fault_shown_until:
                    message = f"{self._fault_note}; {message}"
                else:
                    self._fault_note = ""
            msg.code, msg.code_name, msg.message, msg.condition_number, msg.speed_scale = (
                int(status),
                status.name,
                message,
                condition,
                scale,
            )
            self._status_pub.publish(msg)
        if status != self._last_status:
            self._log_status(status, message)
            self._last_status = status
        if publish:
            with self._lock:  # the next cycle's Jacobian now, while it is off the twist-to-command path
                self._jog.prefetch()

    def _publish_command(self, points: list[tuple[tuple[float, ...], tuple[float, ...], float]]) -> None:
        msg = self._cmd_msg
        with self._pub_lock:  # the twist and timer threads share the message object
            if isinstance(msg, Float64MultiArray):
                msg.data = points[0][1]
            else:
                # Stamp 0: "start now" for joint_trajectory_controller, whatever the transport delay.
                duration = rospy.Duration.from_sec
                msg.points = [
                    JointTrajectoryPoint(positions=q, velocities=v, time_from_start=duration(t))
                    for q, v, t in points
                ]
            self._cmd_pub.publish(msg)

    @staticmethod
    def _log_status(status: StatusCode, message: str) -> None:
        if status in (StatusCode.NO_WARNING, StatusCode.STALE_COMMAND, StatusCode.JOINT_VELOCITY_SCALED):
            rospy.logdebug("jog_arm_server: %s: %s", status.name, message)
        elif status in (StatusCode.PAUSED, StatusCode.NO_JOINT_STATE, StatusCode.CONTACT_GUARD):
            rospy.loginfo("jog_arm_server: %s: %s", status.name, message)
        else:
            rospy.logwarn("jog_arm_server: %s: %s", status.name, message)

    def _on_pause(self, _req: Any) -> TriggerResponse:
        with self._lock:
            self._jog.pause()
        return TriggerResponse(success=True, message="paused: stopping, commands ignored until ~resume")

    def _on_resume(self, _req: Any) -> TriggerResponse:
        with self._lock:
            was_paused = self._jog.paused
            self._jog.resume()
        return TriggerResponse(
            success=True, message="resumed: waiting for a new command" if was_paused else "was not paused"
        )

    def _on_cycle_stats(self, _req: Any) -> TriggerResponse:
        """Cycle timing since the previous call (or start), then starts a new window."""
        summary = self._cycles.summary()
        self._cycles.reset()
        return TriggerResponse(success=True, message=" ".join(f"{k}={v}" for k, v in summary.items()))

    def on_master_lost(self, reason: str) -> None:
        """The graph is broken: stop, and refuse commands until the master is back."""
        rospy.logerr("jog_arm_server: %s: stopping the arm until it returns", reason)
        with self._lock:
            self._jog.suspend(reason)

    def on_master_back(self) -> None:
        with self._lock:
            self._jog.unsuspend()

    def model_frame_pose(self, frame: str, relative_to: str) -> list[list[float]] | None:
        """Pose (4x4 rows) of a robot-model frame in another at the last joint state, for a controller in the
        same process (fresher than tf and no /tf to deserialise); None if either is not a model frame.

        Raises:
            LookupError: No joint state received yet.
        """
        with self._lock:
            return self._jog.measured_frame_pose(frame, relative_to)

    @property
    def settings(self) -> JogSettings:
        return self._s

    def shutdown(self) -> None:
        """Stops the timer and unregisters topics and services."""
        self._closed = True
        if self._timer is not None:
            self._timer.shutdown()
        for sub in self._subs:
            sub.unregister()
        for service in self._services:
            service.shutdown()
        self._cmd_pub.unregister()
        self._status_pub.unregister()


def load(params: dict[str, Any], urdf_xml: str | None, prefix: str) -> tuple[JogSettings, list[str]]:
    """Validates the parameters and the presence of a robot description (no ROS calls).

    Raises:
        SettingsError: Naming the bad key, or the missing robot_description.
    """
    settings, warnings = JogSettings.from_params_with_warnings(params, prefix)
    if not urdf_xml:
        raise SettingsError("robot_description parameter is missing or empty: load the URDF first")
    return settings, warnings


def start(param_ns: str = "~", private_ns: str = "~", skip_callerid: str | None = None) -> JogArmNode | None:
    """A node from the parameters in `param_ns` (after rospy.init_node); None, with a fatal log naming the
    key, if start-up is refused."""
    prefix = rospy.get_name() + "/" if param_ns == "~" else param_ns.rstrip("/") + "/"
    try:
        urdf = rospy.get_param("robot_description", None)
        settings, warnings = load(rospy.get_param(param_ns, {}), urdf, prefix)
        for warning in warnings:
            rospy.logwarn(warning)
        node = JogArmNode(settings, urdf, private_ns, skip_callerid)
    except (SettingsError, KinematicsError) as err:
        rospy.logfatal(f"jog_arm_server refused to start: {err}")
        return None
    rospy.on_shutdown(node.shutdown)
    return node


def main(argv: list[str] | None = None) -> int:
    """Runs the node until shutdown. Returns 1, with a fatal log naming the key, if start-up is refused."""
    rospy.init_node("jog_arm_server", argv=argv)
    node = start()
    if node is None:
        return 1
    MasterWatch(node.on_master_lost, node.on_master_back, params=["~", "robot_description"])
    tune_runtime(node.settings.pub_period)
    rospy.spin()
    return 0


if __name__ == "__main__":
    sys.exit(main())
