"""contact_control_node: the rospy adapter around `ContactControl` (see the package README).

Per wrench: look up the transforms (static ones are cached, each frame at most once per cycle; from the
robot model instead of tf when jog_arm shares the process, see control_stack), run one
`ContactControl.update` and publish the twist at once (lowest latency). A thread wakes when the newest
wrench turns stale and then keeps publishing zero at ~control_rate while a move waits for data. Twists are
published while a move is active (or an axis carries out its exceeded action after it), then
`idle_zero_count` zeros after it ends, then nothing, so other sources (keyboard jogging) can use the same
topic in between. Laws come from the original ConfigureForceControl services or from ConfigureLaws
(`configure_laws`, per axis, answering with the reason).
"""

from __future__ import annotations

import contextlib
import sys
import threading
import time
from collections.abc import Callable, Sequence
from typing import Any

import rospy
import tf2_ros
from cartesian_impedance_msgs.msg import CartesianForceCtrlErrorCodes
from cartesian_impedance_msgs.srv import ConfigureForceControl, ConfigureForceControlResponse
from compliant_common.clock import ClockJump
from compliant_common.master import MasterWatch
from compliant_common.ros_time import JumpAwareClock, sleep_through_jumps, timer
from compliant_common.runtime import tune_runtime
from compliant_control_msgs.msg import AxisState, ContactControlStatus
from compliant_control_msgs.srv import ConfigureLaws, ConfigureLawsResponse
from geometry_msgs.msg import TwistStamped, WrenchStamped
from std_srvs.srv import Trigger, TriggerResponse

from contact_control.axes import (
    AXES,
    END_NAMES,
    EXCEEDED_ACTION_NAMES,
    LAW_COMPLIANT_MOVE,
    LAW_FORCE_TRACKING,
    LAW_NAMES,
    SAFETY_NAMES,
    SAFETY_NO_TF,
)
from contact_control.controller import ContactControl, CycleResult
from contact_control.frames import (
    IDENTITY,
    compose,
    inverse,
    rotate_twist,
    rotation,
    transform,
    transpose_times,
)
from contact_control.params import PARAMETERS, ContactControlSettings, ParamError, load_settings
from contact_control.payload_service import PayloadServices
from contact_control.preprocess import PreprocessError
from contact_control.request import (
    CODE_NAMES,
    SUCCESS,
    RequestError,
    RequestLimits,
    validate_laws_request,
    validate_request,
)

__all__ = [
    "ContactControlNode",
    "describe_laws",
    "fill_status_words",
    "main",
    "read_settings",
]

_ZERO = (0.0,) * 6
FAULT_SHOWN_FOR = 1.0  # [s] a clock jump stays on ~status at least this long, so a 50 Hz reader sees it
_TF_ERRORS = (tf2_ros.LookupException, tf2_ros.ConnectivityException, tf2_ros.ExtrapolationException)
# (frame, relative_to) -> 4x4 rows, None if unknown; raises LookupError while it cannot answer yet.
FrameSource = Callable[[str, str], "list[list[float]] | None"]
TwistSink = Callable[[Sequence[float], str, float], None]


class ContactControlNode:
    """Topics, services, tf and timers around one `ContactControl`; every call into it holds `_lock`.

    Args:
        settings: Validated parameters.
        private_ns: Prefix of the private topics and services: "~" in a node of its own,
            "/contact_control_node/" when sharing a process (control_stack).
        twist_sink: Called as `(velocity, frame, t)` with each twist before it is published (same process:
            no hop, no message): six floats in `velocity_command_frame`, `t` the time of the wrench [s].
        frame_source: `(frame, relative_to) -> 4x4 rows`, None for a frame it does not know, LookupError
            while it cannot answer yet: poses from the robot model (jog_arm in the same process), used before
            tf. tf is then only listened to if some frame is not in the model.
        own_subscribers: Subscriptions to the twist topic inside this process (fed through `twist_sink`): the
            twist is only serialised and sent when somebody else listens too.
    """

    def __init__(
        self,
        settings: ContactControlSettings,
        private_ns: str = "~",
        twist_sink: TwistSink | None = None,
        frame_source: FrameSource | None = None,
        own_subscribers: int = 0,
    ) -> None:
        s = self._s = settings
        self._ctrl = ContactControl(settings)
        self._limits = RequestLimits.from_settings(settings)
        self._lock = threading.Lock()
        self._move_ended = threading.Condition(self._lock)
        self._static: dict[str, list[list[float]]] = {s.fixed_frame: IDENTITY}
        self._frame_source = frame_source
        self._in_model: dict[str, bool] = {}
        self._buffer: tf2_ros.Buffer | None = None
        self._listener: tf2_ros.TransformListener | None = None
        configured = {s.control_frame, s.ft_sensor_frame, s.eef_frame, s.velocity_command_frame}
        from_tf = sorted(f for f in configured - {s.fixed_frame} if not self._model_has(f))
        if from_tf or frame_source is None:
            self._listen_to_tf()
        if frame_source is not None:
            rospy.loginfo("contact_control: frames %s from tf, the others from the robot model",
                          from_tf or "none")
        self._time0 = rospy.Time(0)
        self._gravity = s.tool_mass > 0.0
        self._idle_zeros = 0
        self._was_active = False
        self._request_note = ""
        self._fault_note = ""  # a clock jump or a lost master, for ~status until it is over
        self._fault_shown_until = 0.0  # [s, monotonic] a past fault stays on ~status at least this long
        self._clock = JumpAwareClock()
        self._refusal = RequestError(SUCCESS, "")
        self._accepted = ""
        self._twist_sink = twist_sink
        self._own_subscribers = own_subscribers
        self._twist = TwistStamped()
        self._twist.header.frame_id = s.velocity_command_frame
        # Synchronous: the twist leaves in the wrench callback, ~90 us sooner than through rospy's sender
        # thread. A subscriber that stops reading then blocks this node, and jog_arm halts on its timeout.
        queue = None if s.publish_synchronously else 1
        self._twist_pub = rospy.Publisher(
            s.velocity_out_topic, TwistStamped, queue_size=queue, tcp_nodelay=True
        )
        self._status_pub = rospy.Publisher(private_ns + "status", ContactControlStatus, queue_size=10)
        # The compensated, unfiltered contact force (control frame; torque 0) for jog_arm's contact guard in
        # the two-node layout, sent only while somebody listens. In control_stack jog_arm calls
        # `contact_force` instead. Kept up also while the global limit is latched (the guard needs it most).
        self._contact: tuple[tuple[float, float, float], str, float] | None = None
        self._contact_msg = WrenchStamped()
        self._contact_msg.header.frame_id = s.control_frame
        self._contact_pub = rospy.Publisher(private_ns + "contact_wrench", WrenchStamped, queue_size=1,
                                            tcp_nodelay=True)
        self._status_msg = ContactControlStatus(axes=[AxisState(axis=name) for name in AXES])
        self._status_msg.header.frame_id = s.control_frame
        # Service names in the node's namespace (not private), as the original served them.
        self._services = [
            rospy.Service("configure_cartesian_impedance", ConfigureForceControl, self._on_configure),
            rospy.Service(
                "configure_cartesian_impedance_blocking", ConfigureForceControl, self._on_configure_blocking
            ),
            rospy.Service("configure_laws", ConfigureLaws, self._on_configure_laws),
            rospy.Service(private_ns + "tare", Trigger, self._on_tare),
            rospy.Service(private_ns + "stop", Trigger, self._on_stop),
            rospy.Service(private_ns + "reset", Trigger, self._on_reset),
        ]
        self._payload = PayloadServices(
            private_ns,
            self._sensor_rotation,
            lambda: "a move is running (stop it: the tool must be free)" if self._ctrl.move_active else "",
            self._ctrl.preprocessor.oriented,
            s.gravity,
        )
        self._sub = rospy.Subscriber(
            s.ft_in_topic, WrenchStamped, self._on_wrench, queue_size=1, tcp_nodelay=True
        )
        threading.Thread(target=self._watch_staleness, name="contact_control_staleness", daemon=True).start()
        self._status_timer = timer(1.0 / s.status_rate, self._on_status)
        rospy.on_shutdown(self._on_shutdown)

    # --- tf ---
    def _listen_to_tf(self) -> None:
        self._buffer = tf2_ros.Buffer()
        self._listener = tf2_ros.TransformListener(self._buffer)

    def _model_has(self, frame: str) -> bool:
        """Whether the frame source knows `frame` (relative to the fixed frame); asked once per frame."""
        known = self._in_model.get(frame)
        if known is None:
            source = self._frame_source
            try:
                known = source is not None and source(frame, self._s.fixed_frame) is not None
            except LookupError:  # known, just no joint state yet
                known = True
            self._in_model[frame] = known
        return known

    def _lookup(self, frame: str) -> list[list[float]]:
        """The pose of `frame` in the fixed frame (4x4 rows): from the robot model if it has the frame, else
        from tf (cached when the chain is static)."""
        cached = self._static.get(frame)
        if cached is not None:
            return cached
        if self._model_has(frame):
            return self._frame_source(frame, self._s.fixed_frame)  # type: ignore[misc, return-value]
        if self._buffer is None:  # a wrench in a frame no configured name mentioned
            self._listen_to_tf()
            assert self._buffer is not None  # made by _listen_to_tf
        # The core call: Buffer.lookup_transform adds a can_transform round trip (~4 us) that only waits.
        msg = self._buffer.lookup_transform_core(self._s.fixed_frame, frame, self._time0)
        t, q = msg.transform.translation, msg.transform.rotation
        pose = transform((t.x, t.y, t.z), (q.x, q.y, q.z, q.w))
        if msg.header.stamp.is_zero():  # tf2 answers time 0 only when every link of the chain is static
            self._static[frame] = pose
        return pose

    def _frames(self, sensor_frame: str, need_eef: bool) -> tuple[Any, Any, Any, Any, Any]:
        """(T_control_sensor, R_world_sensor, T_fixed_eef, R_fixed_control, R_command_control) for one cycle.

        Each frame is looked up at most once; None stands for "same frame" or "not needed".
        """
        s = self._s
        poses: dict[str, list[list[float]]] = {}

        def pose(frame: str) -> list[list[float]]:
            if frame not in poses:
                poses[frame] = self._lookup(frame)
            return poses[frame]

        T_fixed_control = pose(s.control_frame)
        R_fixed_control = None if s.control_frame == s.fixed_frame else rotation(T_fixed_control)
        T_control_sensor = None
        if sensor_frame != s.control_frame:
            T_fixed_sensor = pose(sensor_frame)
            if R_fixed_control is None:
                T_control_sensor = T_fixed_sensor
            else:
                T_control_sensor = compose(inverse(T_fixed_control), T_fixed_sensor)
        R_world_sensor = rotation(pose(sensor_frame)) if self._gravity else None
        eef = pose(s.eef_frame) if need_eef else None
        R_command_control = None
        if s.velocity_command_frame != s.control_frame:
            R_fixed_command = rotation(pose(s.velocity_command_frame))
            R_command_control = transpose_times(R_fixed_command, rotation(T_fixed_control))
        return T_control_sensor, R_world_sensor, eef, R_fixed_control, R_command_control

    # --- cycles ---
    def _on_wrench(self, msg: WrenchStamped) -> None:
        t, jump = self._clock.read()
        if jump is not None:
            self._on_clock_jump(jump, t)
            return
        f, q = msg.wrench.force, msg.wrench.torque
        wrench = (f.x, f.y, f.z, q.x, q.y, q.z)
        stamp = msg.header.stamp.to_sec() if not msg.header.stamp.is_zero() else None
        header_frame = "" if self._s.use_ft_sensor_frame else msg.header.frame_id
        sensor_frame = header_frame or self._s.ft_sensor_frame
        if self._payload.sampling:
            self._payload.feed(wrench)
        with self._lock:
            try:
                T_cs, R_ws, eef, R_fc, R_cc = self._frames(sensor_frame, self._ctrl.needs_travel)
            except (*_TF_ERRORS, LookupError) as err:
                self._publish(self._ctrl.hold(t, SAFETY_NO_TF, f"no transform: {err}"), t)
            else:
                self._publish(self._ctrl.update(wrench, t, T_cs, R_ws, eef, R_fc, stamp), t, R_cc)
                if self._ctrl.notes:  # the sensor's measured rate, once per change
                    for note in self._ctrl.notes:
                        rospy.logwarn("contact_control: %s", note)
                    self._ctrl.notes.clear()
                force = self._ctrl.contact_force(wrench, T_cs, R_ws)  # after the twist: off its path
                if force is not None:
                    self._note_contact(force, t)
                if self._frame_source is not None:  # the model caches poses per joint state: fill it now,
                    with contextlib.suppress(*_TF_ERRORS, LookupError):  # off the wrench-to-twist path
                        self._frames(sensor_frame, self._ctrl.needs_travel)

    def _note_contact(self, force: Sequence[float], t: float) -> None:
        """Keeps the compensated contact force for jog_arm's guard (lock held); publishes it if listened."""
        self._contact = ((force[0], force[1], force[2]), self._s.control_frame, t)
        if self._contact_pub.get_num_connections() > 0:
            msg = self._contact_msg
            msg.header.stamp = rospy.Time.from_sec(t)
            f = msg.wrench.force
            f.x, f.y, f.z = force
            self._contact_pub.publish(msg)

    def contact_force(self) -> tuple[tuple[float, float, float], str, float] | None:
        """The latest valid compensated contact force: ((fx, fy, fz) [N], control frame, receive time [s]),
        None before the first; for jog_arm's contact guard in the same process (control_stack)."""
        return self._contact

    def _watch_staleness(self) -> None:
        """Sleeps until the newest wrench turns stale; while data is missing, runs the stale check every
        1/control_rate (zeros for jog_arm, the move's end after no_data_end_timeout). A fixed-rate timer would
        wake the process control_rate times a second for nothing."""
        period = 1.0 / self._s.control_rate
        while not rospy.is_shutdown():
            t, jump = self._clock.read()
            if jump is not None:
                self._on_clock_jump(jump, t)
                wait = period
            else:
                with self._lock:
                    result = self._ctrl.check_stale(t)
                    if result is not None:
                        self._publish(result, t)
                    wait = period if result is not None else max(self._ctrl.fresh_until - t, period)
            try:
                sleep_through_jumps(wait)  # a backward jump ends it early; the next reading reports it
            except rospy.ROSInterruptException:
                return

    def _on_clock_jump(self, jump: ClockJump, t: float) -> None:
        """Halts and restarts the timing; the move resumes with the next wrench stamped after the jump."""
        note = jump.describe()
        rospy.logwarn("contact_control: %s: holding (zero twist) until fresh data", note)
        with self._lock:
            self._fault_note = note
            self._fault_shown_until = time.monotonic() + FAULT_SHOWN_FOR
            self._publish(self._ctrl.clock_jumped(t, note), t)

    # --- master ---
    def on_master_lost(self, reason: str) -> None:
        """The graph is broken: the running move ends and zero twists go out on the existing connections."""
        rospy.logerr("contact_control: %s: ending the move and holding still until it returns", reason)
        with self._lock:
            self._fault_note = reason
            if self._ctrl.stop(reason):
                self._move_ended.notify_all()
                self._was_active = False
                self._idle_zeros = int(self._s.idle_zero_count)
                self._send(_ZERO, rospy.get_time())

    def on_master_back(self) -> None:
        with self._lock:
            self._fault_note = ""

    def _publish(self, result: CycleResult, t: float, R_command_control: Any = None) -> None:
        """Twist out according to the publish policy; wakes blocking callers when a move ends."""
        if result.commanding:  # a move, or an exceeded action after it (moving away, hand-guiding)
            self._idle_zeros = int(self._s.idle_zero_count)
            v = result.velocity
            if R_command_control is not None and any(v):
                v = rotate_twist(R_command_control, v)
            self._send(v, t)
        elif self._was_active:
            self._move_ended.notify_all()
            self._send(_ZERO, t)  # at least one zero right away, whatever idle_zero_count says
        elif self._idle_zeros > 0:
            self._idle_zeros -= 1
            self._send(_ZERO, t)
        elif self._s.publish_when_idle:
            self._send(_ZERO, t)
        self._was_active = result.commanding

    def _send(self, velocity: Sequence[float], t: float) -> None:
        """A twist already expressed in velocity_command_frame, for the wrench (or timer tick) at `t`."""
        if self._twist_sink is not None:
            self._twist_sink(velocity, self._s.velocity_command_frame, t)
        if self._twist_pub.get_num_connections() > self._own_subscribers:
            tw = self._twist
            tw.header.stamp = rospy.Time.from_sec(t)  # the time of the wrench the twist answers
            lin, ang = tw.twist.linear, tw.twist.angular
            lin.x, lin.y, lin.z, ang.x, ang.y, ang.z = velocity
            self._twist_pub.publish(tw)

    # --- services ---
    def _configure(self, req: Any, validate: Callable[..., Any] = validate_request,
                   service: str = "configure_cartesian_impedance") -> int | None:
        """Validates and applies a request (lock held); the new move id, or None when refused."""
        try:
            laws = validate(req, self._limits)
            move_id = self._ctrl.set_laws(laws, None, rospy.get_time())
        except RequestError as err:
            self._refusal = err
            self._request_note = f"last request refused (code {err.code}): {err.message}"
            # The reason first: the original response type cannot carry it, the log and ~status must.
            rospy.logwarn("%s [%s refused: %s (%d)]", err.message, service, CODE_NAMES.get(err.code, "?"),
                          err.code)
            return None
        self._request_note = ""
        self._idle_zeros = int(self._s.idle_zero_count)
        self._move_ended.notify_all()  # a blocking caller of a replaced move answers now
        self._accepted = describe_laws(move_id, laws)
        rospy.loginfo("%s", self._accepted)
        return move_id

    def _on_configure_laws(self, req: Any) -> ConfigureLawsResponse:
        """compliant_control_msgs/ConfigureLaws: per-axis laws; the answer carries the code and the reason."""
        with self._lock:
            if self._configure(req, validate_laws_request, "configure_laws") is None:
                err = self._refusal
                return ConfigureLawsResponse(success=False, code=err.code, message=err.message)
            return ConfigureLawsResponse(success=True, code=SUCCESS, message=self._accepted)

    @staticmethod
    def _response(success: bool) -> ConfigureForceControlResponse:
        # CartesianForceCtrlErrorCodes has constants only, no field: the code goes to the log and ~status.
        return ConfigureForceControlResponse(success=success, error=CartesianForceCtrlErrorCodes())

    def _on_configure(self, req: Any) -> ConfigureForceControlResponse:
        with self._lock:
            return self._response(self._configure(req) is not None)

    def _on_configure_blocking(self, req: Any) -> ConfigureForceControlResponse:
        with self._lock:
            move_id = self._configure(req)
            if move_id is None:
                return self._response(False)
            while True:
                outcome = self._ctrl.move_outcome(move_id)
                if outcome is not None:
                    return self._response(outcome)
                if rospy.is_shutdown():
                    return self._response(False)
                self._move_ended.wait(0.1)

    def _on_tare(self, _req: Any) -> TriggerResponse:
        with self._lock:
            try:
                bias = self._ctrl.tare()
            except PreprocessError as err:
                return TriggerResponse(success=False, message=str(err))
        return TriggerResponse(success=True, message="bias [N, Nm]: " + ", ".join(f"{b:.4g}" for b in bias))

    def _on_stop(self, _req: Any) -> TriggerResponse:
        with self._lock:
            stopped = self._ctrl.stop("stop service")
            if stopped:
                self._move_ended.notify_all()
                self._was_active = False
                self._idle_zeros = int(self._s.idle_zero_count)
                self._send(_ZERO, rospy.get_time())
        return TriggerResponse(success=True, message="move stopped" if stopped else "no move was running")

    def _sensor_rotation(self) -> list[list[float]]:
        """The sensor frame's orientation in the fixed frame now (for payload samples)."""
        with self._lock:
            try:
                return [row[:3] for row in self._lookup(self._s.ft_sensor_frame)[:3]]
            except _TF_ERRORS as err:
                raise LookupError(str(err)) from err

    def _on_reset(self, _req: Any) -> TriggerResponse:
        with self._lock:
            was = self._ctrl.reset_safety()
        message = "safety latch cleared" if was else "safety was not latched"
        return TriggerResponse(success=True, message=message)

    # --- status ---
    def _on_status(self, _event: Any) -> None:
        with self._lock:
            r = self._ctrl.last_result
            note = self._request_note
            fault = self._fault_note
            over = r.safety == 0 and time.monotonic() > self._fault_shown_until
            if fault and over and not fault.startswith("ROS master"):  # the jump is over
                self._fault_note = fault = ""
        msg = self._status_msg  # reused: the status timer allocates nothing per cycle
        msg.header.stamp = rospy.Time.now()
        msg.move_active = r.move_active
        msg.safety = r.safety
        msg.message = "; ".join(m for m in (fault, r.message, note) if m)
        w, v = r.wrench, r.velocity
        f, q = msg.wrench.force, msg.wrench.torque
        f.x, f.y, f.z, q.x, q.y, q.z = w
        lin, ang = msg.velocity.linear, msg.velocity.angular
        lin.x, lin.y, lin.z, ang.x, ang.y, ang.z = v
        for i, axis in enumerate(msg.axes):
            axis.law, axis.end_condition = r.laws[i], r.end_conditions[i]
            axis.force, axis.velocity, axis.travel = w[i], v[i], r.travel[i]
        fill_status_words(msg, r)
        self._status_pub.publish(msg)

    def _on_shutdown(self) -> None:
        with self._lock:
            if self._ctrl.stop("shutdown"):
                self._move_ended.notify_all()
                with contextlib.suppress(rospy.ROSException):  # the publisher may already be closing
                    self._send(_ZERO, rospy.get_time())


def describe_laws(move_id: int, laws: Sequence[Any]) -> str:
    """The accepted laws in words, e.g. "contact laws set (move 3): z=compliant_move (v -0.01, move_away)".

    A compliant move shows its velocity: it may be the default one, in the direction the node chose.
    """
    parts = []
    for i, law in enumerate(laws):
        if law.law:
            notes = [f"v {law.velocity:g}"] if law.law == LAW_COMPLIANT_MOVE else []
            if law.law == LAW_FORCE_TRACKING:
                notes = [f"target {law.target:g}", f"b {law.damping:g}", f"approach {law.velocity:g}"]
            if law.exceeded_action:
                notes.append(EXCEEDED_ACTION_NAMES[law.exceeded_action])
            parts.append(f"{AXES[i]}={LAW_NAMES[law.law]}" + (f" ({', '.join(notes)})" if notes else ""))
    return f"contact laws set (move {move_id}): {', '.join(parts) or 'none (all axes still)'}"


def fill_status_words(msg: Any, result: CycleResult) -> None:
    """The names beside the codes of a ContactControlStatus (so `rostopic echo` reads in words)."""
    msg.safety_name = SAFETY_NAMES.get(result.safety, str(result.safety))
    msg.reacting = any(result.reacting)
    for i, axis in enumerate(msg.axes):
        axis.law_name = LAW_NAMES.get(result.laws[i], str(result.laws[i]))
        axis.end_condition_name = END_NAMES.get(result.end_conditions[i], str(result.end_conditions[i]))
        axis.exceeded_action = EXCEEDED_ACTION_NAMES.get(result.actions[i], "")
        axis.reacting = result.reacting[i]


def read_settings(param_ns: str = "~") -> ContactControlSettings | None:
    """Settings from the parameter server; logs why and returns None when they are invalid."""
    try:
        settings = load_settings(rospy.get_param(param_ns, {}))
    except ParamError as err:
        rospy.logfatal("contact_control_node: bad configuration, not starting: %s", err)
        return None
    return settings


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of `rosrun contact_control contact_control_node`."""
    rospy.init_node("contact_control_node", argv=list(sys.argv if argv is None else argv))
    settings = read_settings()
    if settings is None:
        return 1
    node = ContactControlNode(settings)
    MasterWatch(node.on_master_lost, node.on_master_back, params=["~"])
    tune_runtime(1.0 / settings.control_rate)
    rospy.loginfo(
        "contact_control_node: wrench in %s, twist out %s (%s), control frame %s, %d parameters loaded",
        rospy.resolve_name(settings.ft_in_topic), rospy.resolve_name(settings.velocity_out_topic),
        settings.velocity_command_frame, settings.control_frame, len(PARAMETERS),
    )
    rospy.spin()
    return 0
