"""ContactStage: contact_control without ROS: a wrench (and the frames it needs) in, a twist out.

Around one `ContactControl` it keeps what the node used to: which frames a cycle needs (each looked up once
per cycle), the rotation of the twist into `velocity_command_frame`, the publish policy (twists while a move
or an exceeded action runs, then `idle_zero_count` zeros, then silence so other sources can use the topic),
the stale-data timing (`tick`, `next_due`), requests (validated, answered with the reason), and the notes
shown on `~status`. No rospy: the node (contact_control_node, or control_stack's pipeline) brings the
frames as a `PoseSource` and publishes what comes out.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Sequence
from typing import NamedTuple

from contact_control.axes import (
    AXES,
    EXCEEDED_ACTION_NAMES,
    LAW_COMPLIANT_MOVE,
    LAW_FOLLOWER,
    LAW_FORCE_TRACKING,
    LAW_NAMES,
    LAW_PATH,
    SAFETY_NO_TF,
)
from contact_control.bias_map import BiasMap, BiasMapError, ResidualPredictor, load_bias_map
from contact_control.controller import ContactControl
from contact_control.cycle import CycleResult
from contact_control.events import ContactEvent, EventWatch
from contact_control.frames import IDENTITY, Rows, compose, inverse, rotate_twist, rotation, transpose_times
from contact_control.laws import AxisLaw
from contact_control.params import ContactControlSettings
from contact_control.preprocess import is_finite6
from contact_control.request import (
    FAILURE,
    SUCCESS,
    ForceControlRequest,
    LawsRequest,
    RequestError,
    RequestLimits,
    validate_laws_request,
    validate_request,
)

__all__ = ["Answer", "ContactStage", "PoseSource", "Velocity", "describe_laws"]

#: frame -> its pose in `fixed_frame` (4x4 rows); raises LookupError when it cannot answer (yet).
PoseSource = Callable[[str], "list[list[float]]"]
Velocity = tuple[float, float, float, float, float, float]  # a twist in velocity_command_frame

ZERO: Velocity = (0.0,) * 6
FAULT_SHOWN_FOR = 1.0  # [s] a clock jump stays on ~status at least this long, so a 50 Hz reader sees it


class Answer(NamedTuple):
    """The answer to a request: accepted, its code (request.SUCCESS or why not), the laws in words or the
    reason for refusing, and the move id (0 when refused)."""

    ok: bool
    code: int
    message: str
    move_id: int


class ContactStage:
    """One `ContactControl` with its frames, publish policy and timing; see the module docstring.

    Not thread-safe: the node holds one lock around every call.

    Args:
        settings: Validated parameters.
        poses: Where frames come from (the robot model in control_stack, tf in a node of its own).
        monotonic: The monotonic clock (how long a fault stays on the status).
    """

    def __init__(
        self,
        settings: ContactControlSettings,
        poses: PoseSource,
        monotonic: Callable[[], float] = time.monotonic,
    ) -> None:
        self.settings = s = settings
        self.ctrl = ContactControl(settings)
        self.limits = RequestLimits.from_settings(settings)
        self._poses = poses
        self._monotonic = monotonic
        #: The sensor's offset by pose (`bias_map`), None without one; the load part is compensated like
        #: the tool, the residual follows `on_joint_state`.
        self.bias_map = _bias_map(s)
        if self.bias_map is not None:
            self.ctrl.preprocessor.set_load_error(self.bias_map.mass, self.bias_map.moment)
            self.ctrl.intake.pose_residual = (self.bias_map.residual_force, self.bias_map.residual_torque)
        self._predict: ResidualPredictor | None = None
        self._joint_names: Sequence[str] = ()
        #: Why the bias map's offset is unknown ("": known, or no map): wrenches hold meanwhile.
        self._joints_missing = "no joint state yet" if self.bias_map is not None else ""
        self._gravity = self.ctrl.preprocessor.weighs
        #: The frames a cycle may look up besides the fixed one.
        self.frames_used = frozenset(
            {s.control_frame, s.ft_sensor_frame, s.eef_frame, s.velocity_command_frame} - {s.fixed_frame}
        )
        #: The frame whose axes the running laws act along (a ConfigureLaws request's `frame`, else
        #: control_frame).
        self.frame = s.control_frame
        self._period = 1.0 / s.control_rate
        self._idle_zeros = 0
        self._was_active = False
        self._stale = False  # the last tick found the data stale (then it runs every period)
        self._last_tick = -float("inf")
        self._request_note = ""
        self._fault_note = ""  # a clock jump or a lost master, for ~status until it is over
        self.master_fault = ""  # why the ROS master is lost ('' while it answers)
        self.robot_fault = ""  # why the robot stopped by itself (jog_arm's ~robot_stop), '' while it runs
        self._fault_shown_until = 0.0
        self._cycle_poses: dict[str, list[list[float]]] = {}
        self._last_raw: Sequence[float] = ZERO
        # T_control_sensor, R_world_sensor of that wrench
        self._last_frames: tuple[Rows | None, Rows | None] = (None, None)
        self._have_frames = False
        self._tf_missing = ""  # why the last wrench had no transform ("": it had them)
        self._last_t = 0.0
        #: The latest compensated, unfiltered contact force ((fx, fy, fz) [N], control frame, t [s]) or None.
        self.contact: tuple[tuple[float, float, float], str, float] | None = None
        #: A move ended or was replaced since the node last cleared it (wakes blocking callers).
        self.ended = False
        #: (level, text) for the node's log, drained by it.
        self.notes: list[tuple[str, str]] = []
        self._events = EventWatch(s.event_touch_force, s.event_release_force)
        #: Contact events with the EEF pose, drained by the node (~events).
        self.events: list[ContactEvent] = []
        self._guide_move = 0  # the move id of hand-guiding (0: never guided)

    # --- frames ---
    def _pose(self, frame: str) -> list[list[float]]:
        """Pose of `frame` in the fixed frame, looked up at most once per cycle."""
        pose = self._cycle_poses.get(frame)
        if pose is None:
            pose = IDENTITY if frame == self.settings.fixed_frame else self._poses(frame)
            self._cycle_poses[frame] = pose
        return pose

    def _frames(
        self, sensor_frame: str
    ) -> tuple[Rows | None, Rows | None, Rows | None, Rows | None, Rows | None]:
        """(T_control_sensor, R_world_sensor, T_fixed_eef, R_fixed_control, R_command_control) for one cycle;
        None stands for "same frame" or "not needed".

        Raises:
            LookupError: A frame is not available.
        """
        s = self.settings
        self._cycle_poses.clear()
        control = self.frame
        T_fixed_control = self._pose(control)
        R_fixed_control = None if control == s.fixed_frame else rotation(T_fixed_control)
        T_control_sensor = None
        if sensor_frame != control or sensor_frame != s.eef_frame:
            # Axes: the control frame's; reference point: the end effector, which the twist moves (a push on
            # the tool is no torque there, wherever the control frame's origin is: README, Preprocessing).
            T_fixed_sensor, T_fixed_eef = self._pose(sensor_frame), self._pose(s.eef_frame)
            rows = zip(T_fixed_control[:3], T_fixed_eef[:3], strict=True)
            T_fixed_ref = [*([*row[:3], eef_row[3]] for row, eef_row in rows), IDENTITY[3]]
            T_control_sensor = compose(inverse(T_fixed_ref), T_fixed_sensor)
        R_world_sensor = rotation(self._pose(sensor_frame)) if self._gravity else None
        eef = self._pose(s.eef_frame) if self.ctrl.needs_travel else None
        R_command_control = None
        if s.velocity_command_frame != control:
            R_fixed_command = rotation(self._pose(s.velocity_command_frame))
            R_command_control = transpose_times(R_fixed_command, rotation(T_fixed_control))
        return T_control_sensor, R_world_sensor, eef, R_fixed_control, R_command_control

    def sensor_rotation(self) -> list[list[float]]:
        """The sensor frame's orientation in the fixed frame now (3x3 rows; for payload samples).

        Raises:
            LookupError: Not available.
        """
        self._cycle_poses.clear()
        return [row[:3] for row in self._pose(self.settings.ft_sensor_frame)[:3]]

    # --- data ---
    def on_joint_state(self, names: Sequence[str], positions: Sequence[float]) -> None:
        """Joint positions [rad] (the bias map's residual follows them); nothing without a map."""
        if self.bias_map is None:
            return
        predict = self._predict
        if predict is None or (names is not self._joint_names and tuple(names) != predict.names):
            try:
                predict = self._predict = self.bias_map.predictor(names)
            except BiasMapError as err:
                self._joints_missing = str(err)
                return
        self._joint_names = names
        if len(positions) != len(names):
            self._joints_missing = f"a joint state with {len(positions)} positions for {len(names)} joints"
            return
        offset = predict(positions)
        if not is_finite6(offset):  # a NaN position: the offset is unknown, not zero
            self._joints_missing = "a joint position is not finite"
            return
        self.ctrl.preprocessor.set_pose_bias(offset)
        self._joints_missing = ""

    def on_wrench(
        self, wrench: Sequence[float], frame: str, stamp: float | None, t: float
    ) -> Velocity | None:
        """One cycle for a wrench (fx, fy, fz, tx, ty, tz) [N, Nm] in `frame` ("": ft_sensor_frame) with
        header time `stamp` (None: unstamped) received at `t` [s]; the twist to send, if one is due."""
        s = self.settings
        sensor_frame = ("" if s.use_ft_sensor_frame else frame) or s.ft_sensor_frame
        self._have_frames = False
        try:
            if self._joints_missing:
                raise LookupError(f"the bias map's offset: {self._joints_missing}")
            T_cs, R_ws, eef, R_fc, R_cc = self._frames(sensor_frame)
        except LookupError as err:
            why = f"no transform: {err}" if not self._joints_missing else str(err)
            if why != self._tf_missing:  # logged once per change: only ~status said so before
                self.notes.append(("warn", f"{why}: holding (zero twist) until it comes"))
                self._tf_missing = why
            return self._emit(self.ctrl.hold(t, SAFETY_NO_TF, why))
        if self._tf_missing:
            self.notes.append(("info", "transforms available again"))
            self._tf_missing = ""
        velocity = self._emit(self.ctrl.update(wrench, t, T_cs, R_ws, eef, R_fc, stamp), R_cc)
        if self.ctrl.notes:  # the sensor's measured rate, once per change
            self.notes.extend(("warn", note) for note in self.ctrl.notes)
            self.ctrl.notes.clear()
        self._last_raw, self._last_frames, self._have_frames = wrench, (T_cs, R_ws), True
        self._last_t = t
        return velocity

    def update_contact(self) -> tuple[tuple[float, float, float], str, float] | None:
        """The compensated contact force of the last wrench (for jog_arm's contact guard), computed off the
        wrench-to-twist path: call it after sending the twist. Kept while the global limit is latched (the
        guard needs it most)."""
        if self._have_frames:
            self._have_frames = False
            force = self.ctrl.intake.contact_force(self._last_raw, *self._last_frames)
            if force is not None:
                self.contact = (force, self.frame, self._last_t)
        return self.contact

    # --- time ---
    def next_due(self) -> float:
        """When `tick` has work [s]: when the newest wrench turns stale, then every 1/control_rate while data
        is missing (zeros for jog_arm, the move's end after no_data_end_timeout)."""
        again = self._last_tick + self._period
        return again if self._stale else max(self.ctrl.intake.fresh_until, again)

    def tick(self, t: float) -> Velocity | None:
        """The stale-data check at `t`; the twist to send, if one is due."""
        self._last_tick = t
        result = self.ctrl.check_stale(t)
        self._stale = result is not None
        return None if result is None else self._emit(result)

    def clock_jumped(self, note: str, t: float) -> Velocity | None:
        """Halts and restarts the timing; the move resumes with the next wrench stamped after the jump."""
        self.notes.append(("warn", f"{note}: holding (zero twist) until fresh data"))
        self._fault_note = note
        self._fault_shown_until = self._monotonic() + FAULT_SHOWN_FOR
        self._last_tick = -float("inf")
        return self._emit(self.ctrl.clock_jumped(t, note))

    def note_request(self, note: str) -> None:
        """A word for ~status about a request outside the laws (live tuning), until the next request."""
        self._request_note = note

    def retune(self, settings: ContactControlSettings) -> str:
        """Live tuning with checked settings (ContactControl.retune); what changed, in words."""
        self.settings = settings
        self.limits = RequestLimits.from_settings(settings)
        return "; ".join(self.ctrl.retune(settings))

    def master_lost(self, reason: str) -> Velocity | None:
        """The graph is broken: the running move ends (one zero twist to send)."""
        self._fault_note = self.master_fault = reason
        return self.stop(reason)

    def master_back(self) -> None:
        self._fault_note = self.master_fault = ""

    def robot_stopped(self, reason: str) -> Velocity | None:
        """The robot stopped by itself: the running move ends with the reason (one zero twist to send) and
        requests are refused until :meth:`robot_recovered`."""
        self._fault_note = self.robot_fault = reason
        return self.stop(reason)

    def robot_recovered(self) -> None:
        self._fault_note = self.robot_fault = ""

    def _robot_refusal(self) -> Answer | None:
        if not self.robot_fault:
            return None
        return self._refuse(FAILURE, f"refused: {self.robot_fault}; recover it first "
                                     "(jog_arm_server/recover)")

    # --- publish policy ---
    def _emit(self, result: CycleResult, R_command_control: Rows | None = None) -> Velocity | None:
        """The twist to send for a cycle's result, per the publish policy; notes a move's end."""
        watch = self._events
        watch.observe(result, self.ctrl.end_message)
        if watch.pending:
            self._take_events()
        velocity: Velocity | None = None
        if result.commanding:  # a move, or an exceeded action after it (moving away, hand-guiding)
            self._idle_zeros = int(self.settings.idle_zero_count)
            v = result.velocity
            if R_command_control is not None and any(v):
                v = rotate_twist(R_command_control, v)
            velocity = tuple(v)  # type: ignore[assignment]
        elif self._was_active:
            self.ended = True
            velocity = ZERO  # at least one zero right away, whatever idle_zero_count says
        elif self._idle_zeros > 0:
            self._idle_zeros -= 1
            velocity = ZERO
        elif self.settings.publish_when_idle:
            velocity = ZERO
        self._was_active = result.commanding
        return velocity

    def _take_events(self) -> None:
        """Moves the watch's events to `events`, each with the EEF pose (this cycle's lookup if made)."""
        try:
            pose: Rows | None = self._pose(self.settings.eef_frame)
        except LookupError:
            pose = None
        self.events.extend(e._replace(pose=pose) for e in self._events.pending)
        self._events.pending.clear()

    # --- requests ---
    @property
    def guiding(self) -> bool:
        """Hand-guiding (`guide`) is the running move."""
        ctrl = self.ctrl
        return ctrl.move_active and ctrl.move_id == self._guide_move

    def guide(self, enable: bool, axes: Sequence[str], t: float) -> tuple[Answer, Velocity | None]:
        """Switches hand-guiding on (followers on `axes`, empty: `guide_axes`) or off; the answer and a zero
        twist to send when it stops. Refused, changing nothing, while another move runs."""
        s = self.settings
        if not enable:
            if not self.guiding:
                return Answer(True, SUCCESS, "hand-guiding was not on: nothing changed", 0), None
            return Answer(True, SUCCESS, "hand-guiding off: the arm comes to rest", 0), self.stop(
                "hand-guiding switched off")
        refused = self._robot_refusal()
        if refused is not None:
            return refused, None
        names = tuple(a.strip().lower() for a in axes) or s.guide_axes
        unknown = [a for a in names if a not in AXES]
        if unknown:
            return self._refuse(FAILURE, f"hand-guiding: unknown axis {', '.join(unknown)} (axes are "
                                         f"{', '.join(AXES)})"), None
        ctrl = self.ctrl
        if ctrl.move_active and not self.guiding:
            running = describe_laws(ctrl.move_id, ctrl.laws).replace("contact laws set ", "")
            return self._refuse(FAILURE, f"hand-guiding refused: a contact move is running {running}; stop "
                                         "it first (~stop)"), None
        laws = [AxisLaw()] * 6
        for i, name in enumerate(AXES):
            if name in names:
                angular = i >= 3
                laws[i] = AxisLaw(
                    LAW_FOLLOWER,
                    damping=s.guide_damping_angular if angular else s.guide_damping_linear,
                    velocity=s.guide_max_velocity_angular if angular else s.guide_max_velocity_linear,
                    force_limit=s.guide_torque_limit if angular else s.guide_force_limit,
                    exceeded_action=s.guide_exceeded_action,
                )
        try:
            move_id = ctrl.set_laws(laws, None, t)
        except RequestError as err:
            return self._refuse(err.code, f"hand-guiding refused: {err.message}"), None
        self._guide_move = move_id
        self.frame = s.control_frame  # guiding follows the push along control_frame's axes
        self._request_note = ""
        self._idle_zeros = int(s.idle_zero_count)
        self.ended = True
        guided = " ".join(a for a in AXES if a in names)
        message = (f"hand-guiding on (move {move_id}): {guided} follow the "
                   f"push (b {s.guide_damping_linear:g} N/(m/s), {s.guide_damping_angular:g} Nm/(rad/s); at "
                   f"most {s.guide_max_velocity_linear:g} m/s, {s.guide_max_velocity_angular:g} rad/s)")
        if ctrl.intake.zeroing:
            message += "; the sensor is still being zeroed: keep the tool free until ~status shows safety ok"
        return Answer(True, SUCCESS, message, move_id), None

    def _refuse(self, code: int, message: str) -> Answer:
        self._request_note = f"last request refused (code {code}): {message}"
        return Answer(False, code, message, 0)

    def configure(
        self, req: ForceControlRequest | LawsRequest, t: float, per_axis: bool = False
    ) -> Answer:
        """Validates and applies a ConfigureForceControl (or, `per_axis`, a ConfigureLaws) request:
        (accepted, code, the laws in words or the reason for refusing)."""
        refused = self._robot_refusal()
        if refused is not None:
            return refused
        validate = validate_laws_request if per_axis else validate_request
        try:
            frame = self._request_frame(req if per_axis else None)
            laws, limited = self.ctrl.bound_gains(validate(req, self.limits))
            if frame != self.frame:  # the running move's velocities are along the old frame's axes
                self.ctrl.stop(f"the laws' frame changed from {self.frame} to {frame}")
            move_id = self.ctrl.set_laws(laws, None, t)
            self.frame = frame
        except RequestError as err:
            self._request_note = f"last request refused (code {err.code}): {err.message}"
            return Answer(False, err.code, err.message, 0)
        self._request_note = ""
        self._idle_zeros = int(self.settings.idle_zero_count)
        self.ended = True  # a blocking caller of a replaced move answers now
        message = describe_laws(move_id, laws)
        if self.frame != self.settings.control_frame:
            message += f" (axes of {self.frame})"
        if limited:
            message += "; gains lowered for the sensor's rate: " + ", ".join(limited)
        if self.ctrl.intake.zeroing:
            message += (
                "; the sensor is still being zeroed (at start-up or by ~tare): the laws act once ~status "
                "shows safety ok; keep the tool free until then, a touch now would be taken as the zero"
            )
        return Answer(True, SUCCESS, message, move_id)

    def _request_frame(self, req: LawsRequest | None) -> str:
        """The frame a request's laws act along, checked to be available now (RequestError if not)."""
        s = self.settings
        given = str(getattr(req, "frame", "") or "") if req is not None else ""
        frame = given.lstrip("/") or s.control_frame
        if frame != s.fixed_frame:
            try:
                self._poses(frame)
            except LookupError as err:
                raise RequestError(FAILURE, f"frame: {frame!r} is not available ({err})") from err
        return frame

    def stop(self, reason: str) -> Velocity | None:
        """Ends the running move; a zero twist to send if one was running."""
        if not self.ctrl.stop(reason):
            return None
        self.ended = True
        self._was_active = False
        self._idle_zeros = int(self.settings.idle_zero_count)
        return ZERO

    # --- status ---
    def status(self) -> tuple[CycleResult, str]:
        """The last cycle's result and the status message (fault, cycle, refused request)."""
        r = self.ctrl.last_result
        fault = self._fault_note
        over = r.safety == 0 and self._monotonic() > self._fault_shown_until
        if fault and over and fault not in (self.master_fault, self.robot_fault):  # the jump is over
            self._fault_note = fault = ""
        return r, "; ".join(m for m in (fault, r.message, self._request_note) if m)


def _bias_map(settings: ContactControlSettings) -> BiasMap | None:
    """The settings' bias map, None without one.

    Raises:
        BiasMapError: The file cannot be used, or it holds for another frame than `ft_sensor_frame`.
    """
    if not settings.bias_map:
        return None
    loaded = load_bias_map(settings.bias_map)
    if loaded.frame and loaded.frame != settings.ft_sensor_frame:
        raise BiasMapError(f"bias_map {settings.bias_map}: fitted for the wrench in {loaded.frame!r}, but "
                           f"ft_sensor_frame is {settings.ft_sensor_frame!r}")
    return loaded


def describe_laws(move_id: int, laws: Sequence[AxisLaw]) -> str:
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
            if law.law == LAW_PATH:
                notes = [f"k {law.stiffness:g}", f"b {law.damping:g}"]
                if law.max_travel:
                    notes.append(f"max error {law.max_travel:g}")
            if law.law == LAW_FOLLOWER and law.velocity > 0.0:
                notes.insert(0, f"at most {law.velocity:g}")
            parts.append(f"{AXES[i]}={LAW_NAMES[law.law]}" + (f" ({', '.join(notes)})" if notes else ""))
    return f"contact laws set (move {move_id}): {', '.join(parts) or 'none (all axes still)'}"
