"""JogStage: jog_arm without ROS: joint states and twists in, joint commands out, every timing rule here.

`JogCalcs` does one cycle's arithmetic; this stage decides when cycles run and what surrounds them:
- Cycles run every `pub_period` (`tick`), or, with `publish_on_command`, as soon as a twist arrives, with
  `tick` filling gaps when twists stop (see `timing.FILL_AFTER`).
- Twists from outside sources (keyboard, a GUI, `rostopic pub`) pass the contact guard; twists from a
  controller in the same pipeline (contact_control) do not: they are the contact law's own answer.
- A command whose publisher disconnects is dropped at once (the arm decelerates instead of running for
  `incoming_cmd_timeout` more).
- A clock jump drops the command and waits for a joint state received after it.
No rospy here: the node (jog_arm_server, or control_stack's pipeline) reads the clock and the topics.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Sequence
from typing import NamedTuple

from compliant_common.typedefs import FloatArray

from jog_arm.body_regions import OFF, region_named
from jog_arm.clamp import ClampRelease
from jog_arm.contact_guard import ContactGuard
from jog_arm.jog_calcs import JogCalcs, Point
from jog_arm.model_frames import ModelFrames
from jog_arm.settings import JogSettings
from jog_arm.status import StatusCode
from jog_arm.timing import CycleMonitor, next_fill_time

__all__ = ["ContactSource", "JogCycle", "JogStage", "log_level"]

#: The latest contact force on the tool: ((fx, fy, fz) [N], its frame, the time it was measured [s]), or None.
ContactSource = Callable[[], "tuple[Sequence[float], str, float] | None"]

NOTE_SHOWN_FOR = 1.0  # [s] a clock jump stays in the status at least this long
MISSED_WARNING_EVERY = 10.0  # [s] between warnings about missed cycles
# [s] an outside twist stream counts as going on until it has been silent this long (twists come at 10 Hz
# or more): a push the contact guard stopped, and after a clamp the stream that must pause first
PUSH_GAP = 0.1
# While the contact guard cuts an outside twist, the status says so instead of these (why the arm stops).
_GUARD_OUTRANKS = (StatusCode.NO_WARNING, StatusCode.JOINT_VELOCITY_SCALED, StatusCode.STALE_COMMAND,
                   StatusCode.COLLABORATIVE_SPEED_CAP)


class JogCycle(NamedTuple):
    """What one cycle produced, for the node to publish: a new one per cycle (immutable).

    Attributes:
        t: The cycle's time [s].
        publish: Whether a joint command is due (`positions`, `velocities` and `ahead` are its).
        positions: The command's joint positions [rad] (a trajectory's first point, `pub_period` ahead).
        velocities: The command's joint velocities [rad/s] (also all of a velocity interface's command).
        ahead: A trajectory's further points (simu mode: `simu_points` - 1 extrapolated ones), else ().
        status, message, condition, scale, speed_cap: For the status message.
        status_changed: The status code differs from the previous cycle's (worth a log line).
    """

    t: float
    publish: bool
    positions: tuple[float, ...]
    velocities: tuple[float, ...]
    ahead: tuple[Point, ...]
    status: StatusCode
    message: str
    condition: float
    scale: float
    speed_cap: float
    status_changed: bool


def _jog_cycle(t: float, publish: bool, positions: tuple[float, ...], velocities: tuple[float, ...],
               ahead: tuple[Point, ...], status: StatusCode, message: str, condition: float, scale: float,
               speed_cap: float, status_changed: bool) -> JogCycle:
    """`JogCycle(...)` in one allocation instead of two (see `jog_calcs._jog_output`)."""
    return tuple.__new__(JogCycle, (t, publish, positions, velocities, ahead, status, message, condition,
                                    scale, speed_cap, status_changed))


class JogStage:
    """One arm's jogging: see the module docstring. Not thread-safe: the node holds one lock around calls.

    Args:
        settings: Validated parameters.
        urdf_xml: The robot description.
        contact: Where the contact guard reads the force; None: from `on_contact_wrench` (a topic).
        monotonic: The monotonic clock (for how long a fault stays in the status).

    Raises:
        KinematicsError, SettingsError: The configuration does not fit the robot model.
    """

    def __init__(
        self,
        settings: JogSettings,
        urdf_xml: str,
        contact: ContactSource | None = None,
        monotonic: Callable[[], float] = time.monotonic,
    ) -> None:
        self.settings = s = settings
        self.jog = JogCalcs(settings, urdf_xml)
        self.frames = ModelFrames(self.jog.model, lambda: self.jog.measured)
        self.joint_names = list(self.jog.joint_names)
        self._joint_set = frozenset(self.joint_names)
        self._monotonic = monotonic
        self._period = s.pub_period
        self._points = s.simu_points if s.simu else 1
        self._last_cycle: JogCycle | None = None
        self._last_status = StatusCode.NO_JOINT_STATE
        self._cycles = CycleMonitor(s.pub_period)
        self._next_missed_warning = -math.inf
        self._last_twist_cycle = -math.inf  # publish_on_command: the last cycle a twist ran
        self._last_fill = -math.inf  # publish_on_command: the last cycle tick ran
        self._next_cycle = -math.inf  # timer mode: when the next cycle is due
        self._from_topic = False  # the current command came from an outside source
        self._publishers = 0
        self._fault_note = ""
        self._fault_shown_until = 0.0
        self.suspended = ""  # why commands are refused (a lost ROS master), '' when they are not
        self.robot_stop = ""  # why the robot stopped by itself (robot_stop.RobotStop), '' when it did not
        self.notes: list[tuple[str, str]] = []  # (level, text) for the node's log, drained by it
        self.guard: ContactGuard | None = None
        if s.contact_guard_enabled:
            self.guard = ContactGuard(s.contact_guard_max_force, s.contact_guard_slow_force,
                                      s.contact_guard_slow_speed, s.contact_guard_timeout,
                                      s.contact_guard_relief_speed)
        self._contact: tuple[Sequence[float], str, float] | None = None
        self._contact_source: ContactSource = contact or (lambda: self._contact)
        self._guard_note = ""
        self._guard_acted = False
        self.clamp = ClampRelease(math.inf, math.inf, s.clamp_hold, s.clamp_release_speed,
                                  s.clamp_release_force, s.clamp_release_travel)
        self._push_held = -math.inf  # when the contact guard last held a push into the contact back
        self._last_guarded = -math.inf  # when the last guarded (outside) twist arrived
        self._await_pause = False  # after a clamp: pushes into it are ignored until their stream pauses
        self._away = (0.0, 0.0, 0.0)  # the last clamp's retreat direction (planning_frame)
        self._clamp_limits(s)

    def retune(self, settings: JogSettings) -> None:
        """Live tuning: settings validated by `JogSettings.retuned` (TUNABLE keys only), applied from the next
        cycle (the caller holds the node's lock)."""
        if self.guard is not None:
            self.guard.retune(settings.contact_guard_max_force, settings.contact_guard_slow_force,
                              settings.contact_guard_slow_speed, settings.contact_guard_timeout,
                              settings.contact_guard_relief_speed)
        self.jog.retune(settings)
        self.settings = settings
        self._clamp_limits(settings)

    def _clamp_limits(self, s: JogSettings) -> None:
        """The clamp's limit is the body region's quasi-static force (no region: no clamp release)."""
        c = self.clamp
        c.limit = math.inf if s.collaborative_region == OFF else region_named(s.collaborative_region).force
        c.hold, c.speed, c.release = s.clamp_hold, s.clamp_release_speed, s.clamp_release_force
        c.travel = s.clamp_release_travel
        c.push_limit = s.clamp_push_force if s.contact_guard_enabled else math.inf

    # --- inputs ---
    def on_joint_state(self, names: Sequence[str], positions: Sequence[float], t: float) -> bool:
        """A JointState's names and positions received at `t` [s]. False if it is not usable (a controlled
        joint missing or not finite); a warning is noted only if it names some of our joints (other robots'
        and grippers' states are ignored silently). While moving, the next cycle's twist-independent work
        (Jacobian, factorisation) is done here, off the twist-to-command path."""
        ok = self.jog.set_joint_state_named(names, positions, t)
        if ok:  # the next cycle's Jacobian now, off the twist-to-command path (integrate_from: measured)
            self.jog.prefetch()
        elif self._joint_set.intersection(names):
            self.notes.append(("warn_throttle", "ignoring a joint state that lacks finite positions for "
                               f"{self.joint_names}"))
        return ok

    def on_contact_wrench(self, force: Sequence[float], frame: str, t: float) -> None:
        """The contact force (from contact_control's `~contact_wrench` topic) for the guard."""
        self._contact = (force, frame, t)

    def on_twist(
        self, twist: Sequence[float], frame: str, t: float, outside: bool = True, guarded: bool | None = None
    ) -> JogCycle | None:
        """A velocity command (vx, vy, vz, wx, wy, wz) in `frame` ("": the default) received at `t` [s].

        Args:
            outside: From a topic (keyboard, GUI): it passes the contact guard and is dropped when its
                publisher disconnects. False: from the controller in the same pipeline.
            guarded: Whether it passes the contact guard (None: if `outside`); False for contact_control's
                twists over the topic in the two-node layout (its laws react to the force themselves).

        Returns:
            The cycle it ran (publish_on_command), else None. A refused command is noted for the log and
            makes the arm stop (see `JogCalcs.set_command`).
        """
        frame = frame.lstrip("/")
        is_guarded = outside if guarded is None else guarded
        if is_guarded:
            last, self._last_guarded = self._last_guarded, t
            if self._await_pause and t - last < PUSH_GAP and self._into_clamp(twist, frame):
                return None  # the stream that pushed into the clamp goes on: it must pause first
            self._await_pause = False
        if self.clamp.active:  # releasing a clamp: no command moves the arm until it is released
            return None
        self.jog.braking = False
        if is_guarded and self.guard is not None:
            twist = self._guarded(twist, frame or self.settings.default_cmd_frame, t)
        result = self.jog.set_command(twist, frame, t)
        self._from_topic = outside
        if not result.accepted:
            self.notes.append(("warn_throttle", f"command refused: {result.reason}"))
            return None
        if self.settings.publish_on_command:
            self._last_twist_cycle = t
            return self.cycle(t)
        return None

    def on_publishers(self, count: int) -> None:
        """How many publishers the twist topic has now: one fewer while the command came from it means its
        source died or was stopped, so the command is dropped (the arm stops at once)."""
        if count < self._publishers and self._from_topic:
            self.jog.drop_command("the command's publisher disconnected")
            self._from_topic = False
        self._publishers = count

    def _guarded(self, twist: Sequence[float], frame: str, t: float) -> Sequence[float]:
        """The twist the contact guard lets through (the force turned into the twist's frame)."""
        assert self.guard is not None
        contact = self._contact_source()
        force: tuple[float, ...] | None = None
        age = 0.0
        if contact is not None:
            raw, force_frame, measured = contact
            age = t - measured
            force = tuple(raw)
            if force_frame and force_frame != frame:
                try:
                    pose = self.frames.pose(force_frame, frame)
                except LookupError:
                    pose = None
                if pose is None:  # cannot say which way is into the contact: treat like no fresh force
                    force, age = (math.nan,) * 3, 0.0
                else:
                    force = _rotate(pose, raw)
        result = self.guard.limit(twist, force, age)
        if result.acted and force is not None and _pushes_into(twist, force):
            self._push_held = t
            if result.blocked and result.force >= self.guard.max_force:
                self.jog.braking = True  # a push stopped at the contact: brake as hard as allowed
        if result.message != self._guard_note and result.acted:
            self.notes.append(("warn_throttle", result.message))
        self._guard_note, self._guard_acted = result.message, result.acted
        return result.twist

    def _release_clamp(self, t: float) -> bool:
        """A clamp (clamp.ClampRelease) is released this cycle: the retreat along the force is the command
        (in `planning_frame`); when it ends the arm stops. Whether one is being released."""
        contact, clamp = self._contact_source(), self.clamp
        was = clamp.active
        retreat = None
        if contact is not None and clamp.limit < math.inf:
            raw, frame, measured = contact
            pushed = t - self._push_held <= max(clamp.hold, PUSH_GAP)  # twists come at 10 Hz or more
            retreat = clamp.check(raw, t - measured, self.settings.contact_guard_timeout, t, pushed)
        if retreat is None:
            if was:
                clamp.active = self.jog.braking = False
                self.jog.drop_command(f"clamp released (peak {clamp.peak:.0f} N)")
                self._await_pause = True
                if clamp.stuck:  # the force did not fall: not a contact the retreat can leave
                    self._fault_note = (
                        f"clamp: backed off {clamp.travel * 1e3:.0f} mm and the contact force still reads "
                        f"{clamp.release:g} N or more (peak {clamp.peak:.0f} N): stopped; check the force "
                        "sensor (its zero) or what follows the tool; pushes into it wait until they pause")
                else:
                    self._fault_note = (
                        f"clamp released below {clamp.release:g} N (peak {clamp.peak:.0f} N); pushes into it "
                        "wait until they pause (let go of the key)")
                self._fault_shown_until = self._monotonic() + NOTE_SHOWN_FOR
                self.notes.append(("error" if clamp.stuck else "warn", self._fault_note))
            return False
        s = self.settings
        root, v = s.planning_frame, retreat
        if frame and frame != root:
            try:
                pose = self.frames.pose(frame, root)
            except LookupError:
                pose = None
            if pose is None:  # which way is away is unknown: hold (the contact guard stops outside twists)
                clamp.active = False
                return False
            v = _rotate(pose, v)
        if not was:
            crossed = clamp.limit_words(s.collaborative_region)
            self.notes.append(("warn", f"clamp: {clamp.peak:.0f} N, over {crossed} for {clamp.hold:g} s: "
                               "backing off along the force"))
        self._away = v
        self.jog.braking = True
        unit = s.scale_linear if s.command_in_type == "unitless" else 1.0  # m/s either way
        self.jog.set_command((v[0] / unit, v[1] / unit, v[2] / unit, 0.0, 0.0, 0.0), root, t)
        self._from_topic = False
        return True

    def _into_clamp(self, twist: Sequence[float], frame: str) -> bool:
        """Whether a twist's linear part pushes toward the last clamp (against its retreat); True when its
        frame cannot be turned into planning_frame (refused rather than risked)."""
        root = self.settings.planning_frame
        frame = frame or self.settings.default_cmd_frame
        x, y, z = twist[0], twist[1], twist[2]
        if frame != root:
            try:
                r = self.frames.pose(frame, root)
            except LookupError:
                r = None
            if r is None:
                return True
            x, y, z = _rotate(r, (x, y, z))
        a = self._away
        return _pushes_into((x, y, z), (a[0], a[1], a[2]))

    # --- time ---
    def next_due(self) -> float:
        """When `tick` has a cycle to run [s, the clock of `t`]."""
        if self.settings.publish_on_command:
            return next_fill_time(self._last_twist_cycle, self._last_fill, self._period)
        return self._next_cycle

    def tick(self, t: float) -> JogCycle | None:
        """Runs the cycle due at `t`, if any: every pub_period, or with publish_on_command one to fill a
        gap between twists (then one per period once they stop, to bring the arm to rest)."""
        if t < self.next_due():
            return None
        if self.settings.publish_on_command:
            self._last_fill = t
        else:  # fixed rate; after a stall, restart the schedule instead of catching up with a burst
            due = self._next_cycle + self._period
            self._next_cycle = due if due > t else t + self._period
        return self.cycle(t)

    def clock_jumped(self, note: str) -> None:
        """The clock jumped: stop until a fresh joint state and a new command; restart the schedules."""
        self.notes.append(("warn", f"{note}: stopping until a fresh joint state and a new command"))
        self._last_twist_cycle = self._last_fill = self._next_cycle = -math.inf
        self._fault_note, self._fault_shown_until = note, self._monotonic() + NOTE_SHOWN_FOR
        self.jog.clock_jumped(note)

    # --- the cycle ---
    def cycle(self, t: float) -> JogCycle:
        """One control cycle at `t`: the joint command (if due) and the status."""
        if self._cycles.tick(t) and t >= self._next_missed_warning:
            self._next_missed_warning = t + MISSED_WARNING_EVERY
            self.notes.append(("warn", f"{self._cycles.missed} publish cycles missed so far (longest gap "
                               f"{self._cycles.max_gap * 1e3:.1f} ms, period {self._period * 1e3:g} ms)"))
        releasing = self._release_clamp(t)
        out = self.jog.step(t)
        ahead: tuple[Point, ...] = ()
        if out.publish and self._points > 1:
            ahead = self.jog.points_ahead(out, self._points)
        status, message = out.status, out.message
        if self._guard_acted and self._from_topic and status in _GUARD_OUTRANKS:
            status, message = StatusCode.CONTACT_GUARD, self._guard_note
        if releasing:
            c = self.clamp
            status, message = StatusCode.CLAMP_RELEASE, (
                f"clamp: up to {c.peak:.0f} N, over {c.limit_words(self.settings.collaborative_region)} "
                f"for {c.hold:g} s: backing off along the force at {c.speed:g} m/s until below "
                f"{c.release:g} N")
        if self.robot_stop:
            status, message = StatusCode.ROBOT_STOPPED, (
                f"{self.robot_stop}; commands are refused until recovered (the driver's recovery, then "
                "~recover)")
        if self._fault_note:
            if self._monotonic() < self._fault_shown_until:
                message = f"{self._fault_note}; {message}"
            else:
                self._fault_note = ""
        changed = status != self._last_status
        self._last_status = status
        cycle = self._last_cycle = _jog_cycle(t, out.publish, out.positions, out.velocities, ahead, status,
                                              message, out.condition_number, out.speed_scale, out.speed_cap,
                                              changed)
        return cycle

    @property
    def last_cycle(self) -> JogCycle | None:
        """The last cycle's output (None before the first)."""
        return self._last_cycle

    def prepare(self) -> None:
        """The next cycle's twist-independent work (Jacobian, factorisation) now: call it after publishing,
        off the path from twist to command."""
        self.jog.prefetch()

    # --- modes ---
    def pause(self) -> bool:
        """Pauses; whether it was paused already."""
        was_paused = self.jog.paused
        self.jog.pause()
        return was_paused

    def resume(self) -> str:
        was_paused = self.jog.paused
        self.jog.resume()
        return "resumed: waiting for a new command" if was_paused else "was not paused"

    def suspend(self, reason: str) -> None:
        """Stop, and refuse commands until `unsuspend` (e.g. the ROS master is lost)."""
        self.suspended = reason
        self.jog.suspend(reason)

    def unsuspend(self) -> None:
        self.suspended = ""
        if not self.robot_stop:
            self.jog.unsuspend()

    def robot_stopped(self, reason: str) -> None:
        """The robot stopped by itself (its driver says so): hold with no deceleration to command, refuse
        commands and report ROBOT_STOPPED until :meth:`robot_recovered`."""
        self.robot_stop = reason
        self.clamp.active = False
        self.jog.halt(reason)
        self.notes.append(("error", f"{reason}: holding; commands are refused until recovered"))

    def robot_recovered(self) -> None:
        """The driver runs again and recovery was asked for: commands move the arm again, from the measured
        joints."""
        self.robot_stop = ""
        if self.suspended:  # still suspended (the master lost): the refusal names that again, not the stop
            self.jog.suspend(self.suspended)
        else:
            self.jog.unsuspend()

    @property
    def cycles_run(self) -> int:
        """Cycles run since start (for the cycle rate on /diagnostics)."""
        return self._cycles.total

    def cycle_stats(self) -> str:
        """Cycle timing since the previous call (or start), then a new window."""
        summary = self._cycles.summary()
        self._cycles.reset()
        return " ".join(f"{k}={v}" for k, v in summary.items())

    # --- frames the model lacks ---
    def knows_frame(self, frame: str) -> bool:
        return self.jog.has_frame(frame)

    def add_frame(self, frame: str, parent: str, rotation: FloatArray) -> None:
        """A frame the model lacks, fixed relative to the model frame `parent` (e.g. looked up in tf)."""
        self.jog.add_frame(frame, parent, rotation)


# A push "into" a contact: its linear part within 60 degrees of the direction against the force. A jog
# sideways along a surface, or one a person's push happens to lean on, is not pressing into it.
_INTO_COS = 0.5


def _pushes_into(twist: Sequence[float], away: Sequence[float]) -> bool:
    """Whether a twist's linear part points against `away` (a force on the tool, a retreat), within 60 deg."""
    x, y, z, a, b, c = twist[0], twist[1], twist[2], away[0], away[1], away[2]
    speed, size = math.sqrt(x * x + y * y + z * z), math.sqrt(a * a + b * b + c * c)
    return speed > 0.0 and size > 0.0 and -(x * a + y * b + z * c) >= _INTO_COS * speed * size


def _rotate(r: Sequence[Sequence[float]], v: Sequence[float]) -> tuple[float, float, float]:
    """A 3-vector turned by the rotation block of `r` (3x3 or 4x4 rows)."""
    x, y, z = v[0], v[1], v[2]
    return (r[0][0] * x + r[0][1] * y + r[0][2] * z, r[1][0] * x + r[1][1] * y + r[1][2] * z,
            r[2][0] * x + r[2][1] * y + r[2][2] * z)


def log_level(status: StatusCode) -> str:
    """How loudly a change to `status` is logged: "debug", "info" or "warn"."""
    if status in (StatusCode.NO_WARNING, StatusCode.STALE_COMMAND, StatusCode.JOINT_VELOCITY_SCALED):
        return "debug"
    if status in (StatusCode.PAUSED, StatusCode.NO_JOINT_STATE, StatusCode.CONTACT_GUARD,
                  StatusCode.COLLABORATIVE_SPEED_CAP):  # CLAMP_RELEASE: warn
        return "info"
    return "warn"
