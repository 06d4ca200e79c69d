"""contact_control's ROS surface around a `ContactStage`: services, `~status`, `~contact_wrench`, the twist.

Used by contact_control_node and by control_stack_node (which shares a process with jog_arm); both keep the
same names: services `configure_cartesian_impedance[_blocking]` and `configure_laws` in the node's
namespace, `tare`, `stop`, `reset`, `guide`, `payload/*`, `status`, `events` and `contact_wrench` under the
node's name.
"""

from __future__ import annotations

import contextlib
import threading
from collections.abc import Callable, Sequence

import rospy
import tf2_ros
from cartesian_impedance_msgs.msg import CartesianForceCtrlErrorCodes
from cartesian_impedance_msgs.srv import (
    ConfigureForceControl,
    ConfigureForceControlRequest,
    ConfigureForceControlResponse,
)
from compliant_common.diagnostics import Report
from compliant_common.ros_diagnostics import DiagnosticsPublisher
from compliant_common.ros_live_params import LiveParams
from compliant_common.ros_tf_prefix import for_this_node
from compliant_common.ros_time import TimerEvent, timer
from compliant_common.tf_prefix import TfPrefix
from compliant_control_msgs.msg import AxisState, ContactControlStatus, ContactEvent, PathReference
from compliant_control_msgs.srv import (
    ConfigureLaws,
    ConfigureLawsRequest,
    ConfigureLawsResponse,
    Guide,
    GuideRequest,
    GuideResponse,
)
from geometry_msgs.msg import TwistStamped, WrenchStamped
from std_msgs.msg import String
from std_srvs.srv import Trigger, TriggerRequest, TriggerResponse

from contact_control.axes import AXES, END_NAMES, EXCEEDED_ACTION_NAMES, LAW_NAMES, SAFETY_NAMES
from contact_control.cycle import CycleResult
from contact_control.events import EVENT_NAMES
from contact_control.events import ContactEvent as Event
from contact_control.frames import matrix_quaternion, transform
from contact_control.health import contact_health
from contact_control.params import PARAMETERS, TUNABLE, ContactControlSettings, ParamError, load_settings
from contact_control.payload_service import PayloadServices
from contact_control.request import CODE_NAMES
from contact_control.stage import Answer, ContactStage, Velocity

__all__ = ["ContactControlRos", "TfPoses", "fill_status_words", "read_settings"]

#: What the node does with a twist a request produced (a stop's zero): publish it, and in control_stack
#: also hand it to jog_arm.
Emit = Callable[[Velocity, float], None]


#: [s] a ~tare waits this long beyond its window for a steady one before it gives up.
TARE_TIMEOUT = 5.0

_TF_ERRORS = (tf2_ros.LookupException, tf2_ros.ConnectivityException, tf2_ros.ExtrapolationException)


class TfPoses:
    """A `PoseSource` from tf: the latest pose of a frame in `fixed_frame`; chains tf reports as static
    (stamp 0) are cached. The listener starts on the first question (or `listen()`), so a node that never
    needs tf spends no thread on deserialising /tf."""

    def __init__(self, fixed_frame: str, prefix: TfPrefix | None = None) -> None:
        self._tf = prefix or TfPrefix()
        self._fixed = self._tf.add(fixed_frame)
        self._static: dict[str, list[list[float]]] = {}
        self._buffer: tf2_ros.Buffer | None = None
        self._listener: tf2_ros.TransformListener | None = None
        self._time0 = rospy.Time(0)

    def listen(self) -> None:
        if self._buffer is None:
            self._buffer = tf2_ros.Buffer()
            self._listener = tf2_ros.TransformListener(self._buffer)

    def __call__(self, frame: str) -> list[list[float]]:
        cached = self._static.get(frame)
        if cached is not None:
            return cached
        self.listen()
        assert self._buffer is not None
        try:  # the core call: Buffer.lookup_transform adds a can_transform round trip (~4 us) that only waits
            msg = self._buffer.lookup_transform_core(self._fixed, self._tf.add(frame), self._time0)
        except _TF_ERRORS as err:
            raise LookupError(str(err)) from err
        t, q = msg.transform.translation, msg.transform.rotation
        pose = transform((t.x, t.y, t.z), (q.x, q.y, q.z, q.w))
        if msg.header.stamp.is_zero():  # tf2 answers time 0 only when every link of the chain is static
            self._static[frame] = pose
        return pose


class ContactControlRos:
    """Services, status, events and publishers of contact_control; every stage call holds `lock`.

    Args:
        stage: The contact stage.
        lock: The node's lock around the stage.
        private_ns: Prefix of the private names: "~", or "/contact_control_node/" in control_stack.
        emit: What to do with a twist a request produced (None: publish it).
        local_listeners: Subscribers of the twist topic inside this process: the twist is only serialised
            and sent when somebody else listens too.
    """

    def __init__(
        self,
        stage: ContactStage,
        lock: threading.Lock,
        private_ns: str = "~",
        emit: Emit | None = None,
        local_listeners: int = 0,
    ) -> None:
        s = self._s = stage.settings
        self._stage, self._lock = stage, lock
        self._ended = threading.Condition(lock)
        self._emit = emit or self.send
        self._local = local_listeners
        self.tf = for_this_node()  # frames out get the robot's tf prefix, frames in lose it
        self._twist = TwistStamped()
        self._twist.header.frame_id = self.tf.add(s.velocity_command_frame)
        # Synchronous: the twist leaves in the wrench callback, ~90 us sooner than through rospy's sender
        # thread. A subscriber that stops reading then blocks this node, and jog_arm halts on its timeout.
        queue = None if s.publish_synchronously else 1
        self._twist_pub = rospy.Publisher(s.velocity_out_topic, TwistStamped, queue_size=queue,
                                          tcp_nodelay=True)
        self._status_pub = rospy.Publisher(private_ns + "status", ContactControlStatus, queue_size=10)
        # The compensated, unfiltered contact force (control frame; torque 0) for jog_arm's contact guard in
        # the two-node layout, sent only while somebody listens.
        self._contact_msg = WrenchStamped()
        self._contact_msg.header.frame_id = self.tf.add(s.control_frame)
        self._contact_pub = rospy.Publisher(private_ns + "contact_wrench", WrenchStamped, queue_size=1,
                                            tcp_nodelay=True)
        # Rare (a touch, a move's end): published from the cycle that found them, latched for late joiners.
        self._events_pub = rospy.Publisher(private_ns + "events", ContactEvent, queue_size=20, latch=True)
        self._path_sub = rospy.Subscriber(private_ns + "path_reference", PathReference,
                                          self._on_path_reference, queue_size=1, tcp_nodelay=True)
        self._robot_stop_sub = rospy.Subscriber(s.robot_stop_topic, String, self._on_robot_stop, queue_size=5,
                                                tcp_nodelay=True)
        self._status_msg = ContactControlStatus(axes=[AxisState(axis=name) for name in AXES])
        self._status_msg.header.frame_id = self.tf.add(s.control_frame)
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
            rospy.Service(private_ns + "guide", Guide, self._on_guide),
        ]
        self.payload = PayloadServices(
            private_ns,
            self._sensor_rotation,
            lambda: "a move is running (stop it: the tool must be free)" if stage.ctrl.move_active else "",
            stage.ctrl.preprocessor.oriented,
            s.gravity,
        )
        self._status_timer = timer(1.0 / s.status_rate, self._on_status)
        self._health_name = rospy.resolve_name(private_ns).rstrip("/")  # contact_control_node in both layouts
        self._health = DiagnosticsPublisher(self._health_report, s.ft_sensor_frame)
        self._live = LiveParams(PARAMETERS, TUNABLE, PARAMETERS.values_of(s), self._retune, private_ns)

    # --- out ---
    def send(self, velocity: Sequence[float] | None, t: float) -> None:
        """Publishes a twist (velocity_command_frame) answering the wrench or tick at `t`, if listened."""
        if velocity is not None and self._twist_pub.get_num_connections() > self._local:
            tw = self._twist
            tw.header.stamp = rospy.Time.from_sec(t)  # the time of the wrench the twist answers
            lin, ang = tw.twist.linear, tw.twist.angular
            lin.x, lin.y, lin.z, ang.x, ang.y, ang.z = velocity
            self._twist_pub.publish(tw)

    def send_contact(self) -> None:
        """Publishes the latest contact force on `~contact_wrench` if somebody listens (lock held)."""
        if self._contact_pub.get_num_connections() > 0:
            contact = self._stage.contact
            if contact is not None:
                force, frame, t = contact
                msg = self._contact_msg
                msg.header.stamp = rospy.Time.from_sec(t)
                msg.header.frame_id = self.tf.add(frame)
                f = msg.wrench.force
                f.x, f.y, f.z = force
                self._contact_pub.publish(msg)

    def after(self) -> None:
        """Logs the stage's notes and wakes blocking callers whose move ended (lock held)."""
        stage = self._stage
        if stage.notes:
            for level, text in stage.notes:
                (rospy.logwarn if level.startswith("warn") else rospy.loginfo)("contact_control: %s", text)
            stage.notes.clear()
        if stage.events:
            for event in stage.events:
                self._events_pub.publish(self._event_msg(event))
            stage.events.clear()
        if stage.ended:
            stage.ended = False
            self._ended.notify_all()

    def _event_msg(self, event: Event) -> ContactEvent:
        msg = ContactEvent(type=event.kind, type_name=EVENT_NAMES[event.kind], move_id=event.move_id,
                           message=event.message)
        msg.header.stamp = rospy.Time.from_sec(event.t)
        msg.header.frame_id = self.tf.add(self._stage.frame)
        f, q = msg.wrench.force, msg.wrench.torque
        f.x, f.y, f.z, q.x, q.y, q.z = event.wrench
        if event.pose is not None:
            msg.pose.header.stamp = msg.header.stamp
            msg.pose.header.frame_id = self.tf.add(self._s.fixed_frame)
            p, o = msg.pose.pose.position, msg.pose.pose.orientation
            p.x, p.y, p.z = (row[3] for row in event.pose[:3])
            o.x, o.y, o.z, o.w = matrix_quaternion(event.pose)
        return msg

    def emit_locked(self, velocity: Velocity | None, t: float) -> None:
        """Hands a twist a request or a fault produced to `emit` (lock held)."""
        if velocity is not None:
            self._emit(velocity, t)
        self.after()

    # --- requests ---
    def _configure(
        self, req: ConfigureForceControlRequest | ConfigureLawsRequest, per_axis: bool, service: str
    ) -> Answer:
        answer = self._stage.configure(req, rospy.get_time(), per_axis)
        if answer.ok:
            rospy.loginfo("%s", answer.message)
        else:  # the reason first: the original response type cannot carry it, the log and ~status must
            name = CODE_NAMES.get(answer.code, "?")
            rospy.logwarn("%s [%s refused: %s (%d)]", answer.message, service, name, answer.code)
        self.after()
        return answer

    def _on_configure_laws(self, req: ConfigureLawsRequest) -> ConfigureLawsResponse:
        """compliant_control_msgs/ConfigureLaws: per-axis laws; the answer carries the code and the reason."""
        with self._lock:
            answer = self._configure(req, True, "configure_laws")
        return ConfigureLawsResponse(success=answer.ok, code=answer.code, message=answer.message)

    def _on_guide(self, req: GuideRequest) -> GuideResponse:
        """compliant_control_msgs/Guide: hand-guiding on the chosen axes, or off; the answer says why not."""
        with self._lock:
            t = rospy.get_time()
            answer, zero = self._stage.guide(req.enable, list(req.axes), t)
            (rospy.loginfo if answer.ok else rospy.logwarn)("contact_control: %s", answer.message)
            self.emit_locked(zero, t)
        return GuideResponse(success=answer.ok, code=answer.code, message=answer.message)

    def _on_path_reference(self, msg: PathReference) -> None:
        """The path law's reference (fixed frame), timed by its arrival on this node's clock."""
        frame = msg.header.frame_id
        if frame and self.tf.bare(frame) != self._s.fixed_frame:
            rospy.logwarn_throttle(5.0, "contact_control: ~path_reference in %s ignored: it must be in %s",
                                   frame, self._s.fixed_frame)
            return
        p, q, v, w = msg.pose.position, msg.pose.orientation, msg.velocity.linear, msg.velocity.angular
        horizon = [((h.position.x, h.position.y, h.position.z),
                    (h.orientation.x, h.orientation.y, h.orientation.z, h.orientation.w))
                   for h in msg.horizon]
        with self._lock:
            why = self._stage.ctrl.set_path_reference((p.x, p.y, p.z), (q.x, q.y, q.z, q.w),
                                                      (v.x, v.y, v.z, w.x, w.y, w.z), rospy.get_time(),
                                                      horizon, msg.horizon_step)
        if why:
            rospy.logwarn_throttle(5.0, "contact_control: %s", why)

    @staticmethod
    def _response(success: bool) -> ConfigureForceControlResponse:
        # CartesianForceCtrlErrorCodes has constants only, no field: the code goes to the log and ~status.
        return ConfigureForceControlResponse(success=success, error=CartesianForceCtrlErrorCodes())

    def _on_configure(self, req: ConfigureForceControlRequest) -> ConfigureForceControlResponse:
        with self._lock:
            return self._response(self._configure(req, False, "configure_cartesian_impedance").ok)

    def _on_configure_blocking(self, req: ConfigureForceControlRequest) -> ConfigureForceControlResponse:
        with self._lock:
            answer = self._configure(req, False, "configure_cartesian_impedance_blocking")
            if not answer.ok:
                return self._response(False)
            while True:
                outcome = self._stage.ctrl.move_outcome(answer.move_id)
                if outcome is not None:
                    return self._response(outcome)
                if rospy.is_shutdown():
                    return self._response(False)
                self._ended.wait(0.1)

    def _on_tare(self, _req: TriggerRequest) -> TriggerResponse:
        """Zeroes over a steady window as at start-up (the laws hold still meanwhile) and answers with the
        bias and the noise floor; gives up, keeping the old bias, after `TARE_TIMEOUT` s more than the
        window without a steady one (the reason in the answer)."""
        with self._lock:
            ctrl = self._stage.ctrl
            if ctrl.intake.last_raw is None:
                return TriggerResponse(success=False, message="no wrench received yet: the bias is unchanged")
            ctrl.intake.start_zeroing()
            deadline = rospy.get_time() + self._s.tare_window + TARE_TIMEOUT
            while ctrl.intake.zeroing:
                if rospy.is_shutdown() or rospy.get_time() > deadline:
                    why = ctrl.intake.cancel_zeroing()
                    return TriggerResponse(success=False, message=f"not zeroed, the bias is unchanged: {why}")
                self._ended.wait(0.02)  # releases the lock for the wrenches being averaged
            bias = ctrl.preprocessor.bias
            floor = ctrl.intake.noise_floor
        message = "bias [N, Nm]: " + ", ".join(f"{b:.4g}" for b in bias)
        return TriggerResponse(success=True, message=message + ("; " + floor.describe() if floor else ""))

    def _on_stop(self, _req: TriggerRequest) -> TriggerResponse:
        with self._lock:
            zero = self._stage.stop("stop service")
            self.emit_locked(zero, rospy.get_time())
        return TriggerResponse(success=True, message="move stopped" if zero else "no move was running")

    def _on_reset(self, _req: TriggerRequest) -> TriggerResponse:
        with self._lock:
            was = self._stage.ctrl.reset_safety()
        message = "safety latch cleared" if was else "safety was not latched"
        return TriggerResponse(success=True, message=message)

    def _sensor_rotation(self) -> list[list[float]]:
        with self._lock:
            return self._stage.sensor_rotation()

    # --- faults ---
    def master_lost(self, reason: str) -> None:
        rospy.logerr("contact_control: %s: ending the move and holding still until it returns", reason)
        with self._lock:
            self.emit_locked(self._stage.master_lost(reason), rospy.get_time())

    def master_back(self) -> None:
        with self._lock:
            self._stage.master_back()

    def _on_robot_stop(self, msg: String) -> None:
        """jog_arm says the robot stopped by itself (or runs again: '')."""
        with self._lock:
            if msg.data and msg.data != self._stage.robot_fault:
                rospy.logerr("contact_control: %s: ending the move; requests are refused until recovered",
                             msg.data)
                self.emit_locked(self._stage.robot_stopped(msg.data), rospy.get_time())
            elif not msg.data and self._stage.robot_fault:
                self._stage.robot_recovered()
                rospy.loginfo("contact_control: the robot runs again: requests are taken")

    def shutdown(self) -> None:
        """Ends a running move with a zero twist."""
        self._health.close()
        with self._lock, contextlib.suppress(rospy.ROSException):  # the publisher may already be closing
            self.emit_locked(self._stage.stop("shutdown"), rospy.get_time())

    # --- live tuning ---
    def _retune(self, changed: dict[str, object]) -> str:
        """dynamic_reconfigure's change: the whole settings checked as at start-up, then applied under the
        lock (ContactStage.retune); '' or why it is refused (nothing changed then)."""
        try:
            settings = load_settings({**PARAMETERS.values_of(self._s), **changed})
        except ParamError as err:
            with self._lock:
                self._stage.note_request(f"live tuning refused: {err}")
            return str(err)
        with self._lock:
            words = self._stage.retune(settings)
            self._s = settings
            self._stage.note_request("tuned " + ", ".join(f"{k}={v}" for k, v in changed.items())
                                     + (f" ({words})" if words else ""))
        return ""

    # --- health ---
    def _health_report(self) -> Report:
        """contact_control's /diagnostics (its own thread, once every 0.1 s; contact_control.health)."""
        stage, ctrl = self._stage, self._stage.ctrl
        with self._lock:  # only the reads: the words are made outside
            r, message = stage.status()
            last, now = ctrl.intake.last_wrench_time, rospy.get_time()
            period, timeout = ctrl.intake.sample_period, ctrl.intake.wrench_timeout
            floor, drift = ctrl.intake.noise_floor, ctrl.intake.zero_drift
            master, guiding, stopped = stage.master_fault, stage.guiding, stage.robot_fault
        age = None if last is None else max(0.0, now - last)
        return contact_health(self._health_name, self._s, r, message, period, age, timeout, floor, drift,
                              master, guiding, stopped)

    # --- status ---
    def _on_status(self, _event: TimerEvent | None) -> None:
        if self._status_pub.get_num_connections() == 0:  # nobody listening: save the work
            return
        with self._lock:  # stamped under the lock: no status older than a request is stamped after its answer
            stamp = rospy.Time.now()
            r, message = self._stage.status()
            guiding = self._stage.guiding
            # The move's state now, not the last cycle's: after ~stop (or a new law) the next cycle waits for
            # the next wrench, and a status in between said the stopped move still ran (teach refused a
            # replay just after hand-guiding was switched off: "a contact move is running").
            active, reacting = self._stage.ctrl.move_active, any(self._stage.ctrl.reacting())
        msg = self._status_msg  # reused: the status timer allocates nothing per cycle
        msg.header.frame_id = self.tf.add(self._stage.frame)
        msg.header.stamp = stamp
        msg.guiding = guiding
        msg.safety = r.safety
        msg.message = message
        w, v = r.wrench, r.velocity
        f, q = msg.wrench.force, msg.wrench.torque
        f.x, f.y, f.z, q.x, q.y, q.z = w
        lin, ang = msg.velocity.linear, msg.velocity.angular
        lin.x, lin.y, lin.z, ang.x, ang.y, ang.z = v
        for i, axis in enumerate(msg.axes):
            axis.law, axis.end_condition = r.laws[i], r.end_conditions[i]
            axis.force, axis.velocity, axis.travel = w[i], v[i], r.travel[i]
        floor = self._stage.ctrl.intake.noise_floor
        if floor is not None and not msg.noise_std:
            msg.noise_std, msg.noise_filtered = list(floor.std), list(floor.filtered)
        drift = self._stage.ctrl.intake.zero_drift
        if drift is not None:
            msg.zero_drift = list(drift)
        fill_status_words(msg, r)
        msg.move_active, msg.reacting = active, reacting
        self._status_pub.publish(msg)


def fill_status_words(msg: ContactControlStatus, result: CycleResult) -> None:
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
