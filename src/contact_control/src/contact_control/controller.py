"""ContactControl: wrench preprocessing plus the six axis laws, one `update` per wrench (no ROS here).

How a move starts, ends and resumes after NaN, stale or over-limit data: the package README, *Moves and how
they end* and *Safety*. A move that ended on a force limit hands over to its axes' exceeded actions
(`exceeded`); twists keep coming while one runs (`CycleResult.commanding`).

Not thread-safe: the node serialises calls with one lock.
"""

from __future__ import annotations

from collections.abc import Sequence

from contact_control.axes import End, Law, Safety
from contact_control.cycle import CycleResult
from contact_control.ends import EndChecks, end_reason
from contact_control.exceeded import ExceededReaction
from contact_control.force_integral import ForceIntegral
from contact_control.global_limit import GlobalLimit
from contact_control.intake import WrenchIntake
from contact_control.law_set import LawSet
from contact_control.laws import AxisLaw, law_velocity, path_velocity, shape_velocity
from contact_control.loop_gain import GainBound
from contact_control.move import MoveState
from contact_control.normal import NormalFollower, normal_velocity
from contact_control.oscillation import OscillationGuard
from contact_control.params import ContactControlSettings
from contact_control.path_ref import PathReference
from contact_control.preprocess import Matrix
from contact_control.request import FAILURE, RequestError
from contact_control.travel import MoveTravel

__all__ = ["ContactControl"]


class ContactControl:
    """The six axis laws over one wrench stream; see the module docstring for the stop/resume rules.

    A cycle (`update`) takes the wrench in (`intake.WrenchIntake`, then the preprocessor), checks the move's
    ends, computes the velocities and watches for oscillation; the move's state is a `move.MoveState`, its
    laws a `law_set.LawSet` compiled once per request.
    """

    def __init__(self, settings: ContactControlSettings | None = None) -> None:
        s = settings or ContactControlSettings()
        self.settings = s
        self.notes: list[str] = []  # what the node should log once (the sensor's measured rate, ...)
        self.intake = WrenchIntake(s, self.notes, on_floor=self._watch_floor_update)
        self.preprocessor = self.intake.preprocessor
        self._tuning = tuple(s.tuning(i >= 3) for i in range(6))
        self._end_timeout, self._dt_nominal = s.no_data_end_timeout, 1.0 / s.control_rate
        self._ends = EndChecks(tuple(t.diff_max for t in self._tuning), s.diff_window, s.force_limit_arm_time,
                               int(s.force_limit_samples))
        self._moved = MoveTravel(s.travel_directions)
        self._reaction = ExceededReaction(self._tuning, s.move_away_release_fraction)
        self._set, self._shown = LawSet(), [int(Law.NONE)] * 6  # _shown: what runs now (a follower, reacting)
        self._path = PathReference(s.path_reference_timeout, s.path_extrapolate)
        self._path_error, self._path_velocity = [0.0] * 6, [0.0] * 6
        self._normal = NormalFollower.of(s)
        self._integral = ForceIntegral()
        self._v, self._wrench = [0.0] * 6, [0.0] * 6
        self._move = MoveState()
        self._last_t: float | None = None
        self._gain_bound = GainBound(s.loop_gain_delay, s.command_latency, s.spring_output_scale,
                                     s.contact_stiffness)
        self._global = GlobalLimit(int(s.force_limit_samples))
        self._watch = (OscillationGuard(int(s.oscillation_reversals), s.oscillation_window, self._tuning)
                       if s.oscillation_reversals > 0 else None)
        self._requested: list[AxisLaw] = []  # the laws as last requested (the watchdog may lower them)
        self.last_result = self._result(0.0, Safety.STALE, "no wrench yet")

    # --- state ---
    @property
    def move_active(self) -> bool:
        return self._move.active

    @property
    def move_id(self) -> int:
        return self._move.id

    def reacting(self) -> list[bool]:
        """Per axis, carrying out its exceeded action now (`last_result.reacting` is the last cycle's)."""
        return self._reaction.reacting()

    @property
    def end_ok(self) -> bool:
        """Whether the last move ended by an axis end condition (force limit, max travel, force jump)."""
        return self._move.ok

    def move_outcome(self, move_id: int) -> bool | None:
        """None while move `move_id` runs; then whether it ended by an axis end condition (see `end_ok`).
        A blocking caller hears of the end once the press is released (moving away)."""
        return self._move.outcome(move_id, self._move.active or self._reaction.moving_away)

    @property
    def end_message(self) -> str:
        return self._move.message

    @property
    def laws(self) -> tuple[AxisLaw, ...]:
        return self._set.laws

    @property
    def needs_travel(self) -> bool:
        """Whether the running move uses travel (spring, compliant move, max travel): needs EEF poses."""
        return self._move.active and self._set.needs_travel

    def bound_gains(self, laws: Sequence[AxisLaw]) -> tuple[list[AxisLaw], list[str]]:
        """The laws with their loop gains within what the sensor's measured rate (`lp_filter_delta_t` until
        measured) and the command latency keep stable, and a note per lowered gain (see `loop_gain`)."""
        return self._gain_bound.limit(laws, *self.intake.loop_timing())

    # --- commands ---
    def set_laws(self, laws: Sequence[AxisLaw], eef_pose: Matrix | None = None, t: float | None = None,
                 R_fixed_control: Matrix | None = None) -> int:
        """Starts a move with six validated laws (x, y, z, rx, ry, rz; `request.validate_request`), replacing
        any running move at once, and returns its id. `eef_pose`: the 4x4 EEF pose in the fixed frame at the
        start (None: the next `update`'s); `t`: now [s] (for the no-data end timeout); `R_fixed_control`: the
        control frame's orientation at the start (None: the fixed frame's). Raises RequestError (the global
        safety is latched: reset first) or ValueError (not six AxisLaw); either way nothing changes."""
        laws = list(laws)
        if len(laws) != 6 or not all(isinstance(law, AxisLaw) for law in laws):
            raise ValueError("set_laws needs six AxisLaw (x, y, z, rx, ry, rz)")
        if self._move.latched:
            raise RequestError(FAILURE, f"safety latched ({self._move.latch_message}); call reset first")
        self.intake.check_resolvable(laws)
        if self._move.active and laws == self._requested:
            return self._move.id  # a re-sent request (GUI Apply held, a script in a loop): nothing changes
        self._requested = laws
        if self.intake.drift is not None:
            self.intake.drift.restart()
        self._ends.clear_over()
        if self._watch is not None:
            self._watch.clear()
        if self._move.active and any(law.law for law in laws):
            return self._change_laws(laws, t)
        if self._move.active:
            self._end_move(-1, End.EXTERNAL_STOP, False, "replaced by a new request")
        self._reaction.clear()
        self._adopt(laws, fresh=True)
        self._ends.restart(t)
        self._v = [0.0] * 6
        self._normal.reset()
        self._moved.restart(eef_pose, R_fixed_control)
        self._path.begin(t)
        self._last_t = None
        return self._move.begin(bool(self._set.active), t)

    def _adopt(self, laws: list[AxisLaw], fresh: bool = False) -> None:
        """Six laws compiled for the cycles (a new move's, `fresh`, or a changed one's)."""
        self._set = LawSet.of(laws, self._ends.diff, self.settings.force_tracking_fast_guard)
        self._integral.adopt(self._set, fresh)
        self._shown = list(self._set.types)
        self.preprocessor.keep_fast = any(self._set.guarded)
        self._watch_floor_update()

    def _change_laws(self, laws: list[AxisLaw], t: float | None) -> int:
        """Bumpless re-configuration of a running move: an axis that keeps its law type keeps its velocity,
        travel and force-limit arming (new parameters apply from its current state, within the rate limits);
        an axis whose law changes starts from rest, its travel from here. The move gets a new id (a blocking
        caller of the old request is answered), but nothing stops."""
        old, kept = self._set.types, list(self._v)
        self._end_move(-1, End.EXTERNAL_STOP, False, "changed by a new request")
        self._v = kept
        for i, law in enumerate(laws):
            if law.law != old[i] or not law.law:
                self._v[i] = 0.0
                self._moved.restart_axis(i)
                self._ends.restart_axis(i)
        self._ends.started(t)
        if any(law.law == Law.PATH and law.law != old[i] for i, law in enumerate(laws)):
            self._path.begin(t)
        self._adopt(laws)
        return self._move.change()

    def set_path_reference(self, position: Sequence[float], quaternion: Sequence[float],
                           twist: Sequence[float], t: float,
                           horizon: Sequence[tuple[Sequence[float], Sequence[float]]] = (),
                           step: float = 0.0) -> str:
        """The path law's reference at time `t` [s] and its horizon (fixed frame; see
        `path_ref.PathReference.set`): '' or why it is refused."""
        return self._path.set(position, quaternion, twist, t, horizon, step)

    def clock_jumped(self, t: float, description: str) -> CycleResult:
        """The clock jumped (see compliant_common.clock): every duration measured across it is wrong, so the
        output halts and the timing restarts at `t` (no wrench counts as received, the no-data end timeout and
        force-limit arming restart); the move resumes with the next wrench stamped after the jump."""
        self.intake.restart_timing()
        self._last_t = None
        if self._move.active:
            self._move.t0 = t
        self._ends.clear_windows()
        return self._hold(t, Safety.STALE, f"{description}: timing reset, holding until fresh data")

    def stop(self, reason: str = "stop requested") -> bool:
        """Ends the running move (EXTERNAL_STOP) or exceeded action; returns whether one was running."""
        if not self._move.active:
            return self._stop_reaction(reason)
        self._end_move(-1, End.EXTERNAL_STOP, False, reason)
        return True

    def reset_safety(self) -> bool:
        """Clears a latched global-limit trip; returns whether it was latched."""
        return self._move.unlatch()

    def retune(self, s: ContactControlSettings) -> list[str]:
        """Live tuning (params.TUNABLE): new limits, deadbands, filter cutoff and global limits from checked
        settings, applied bumplessly: the velocity commanded last stays, and the next cycles reach the new
        clamp within the acceleration and deceleration limits; the filter continues from its last output.
        Returns what changed, in words."""
        self.settings = s
        self._tuning = tuple(s.tuning(i >= 3) for i in range(6))
        self._ends.diff = tuple(t.diff_max for t in self._tuning)
        self._reaction.retune(self._tuning)
        self._normal.tune(s)
        self._watch_floor_update()
        return self.intake.retune(s)

    # --- cycles ---
    def update(self, wrench: Sequence[float], t: float, T_control_sensor: Matrix | None = None,
               R_world_sensor: Matrix | None = None, eef_pose: Matrix | None = None,
               R_fixed_control: Matrix | None = None, stamp: float | None = None) -> CycleResult:
        """One control cycle for a received wrench (fx, fy, fz, tx, ty, tz) [N, Nm] in the sensor frame,
        received at `t` [s] (every call's clock), stamped `stamp` [s] (None: not stamped; older than
        wrench_timeout counts as no data). Poses: the sensor in the control frame (4x4; None: the same
        frame), the sensor's orientation in the fixed frame (3x3, tool gravity), the EEF in the fixed frame
        (4x4, travel; None: not updated), the control frame's orientation in the fixed frame (None: same)."""
        w = self._accept(wrench, t, stamp, T_control_sensor, R_world_sensor)
        if isinstance(w, CycleResult):
            return w
        if not self._move.active:
            if self._reaction.active:
                return self._react(t, w)
            self.intake.watch_drift(wrench, R_world_sensor, t)
            return self._result(t, Safety.OK, "")
        self._moved.measure(eef_pose, R_fixed_control)
        ended = self._check_ends(t, w, eef_pose, R_fixed_control)
        if ended is not None:
            return ended
        self._step_velocities(t, w, T_control_sensor, R_fixed_control)
        stopped = self._watch_oscillation(t)
        if stopped is not None:
            return stopped
        self._ends.arm(t)
        return self._result(t, Safety.OK, self._normal.message if self._set.normal_axes else "")

    def _accept(self, wrench: Sequence[float], t: float, stamp: float | None, T_control_sensor: Matrix | None,
                R_world_sensor: Matrix | None) -> list[float] | CycleResult:
        """The wrench in the control frame, or the cycle's result when the output holds (stale, NaN, zeroing,
        over a global limit, latched)."""
        held = self.intake.receive(wrench, t, stamp, R_world_sensor)
        if held is not None:
            return self._hold(t, *held)
        code, w = self.preprocessor.process(wrench, T_control_sensor, R_world_sensor)
        if code == Safety.NAN:
            return self._hold(t, Safety.NAN, "wrench contains NaN or inf: holding until valid data")
        if self._global.spike(code != Safety.OK, self._move.latched):
            return self._result(t, Safety.OK, "")
        if code != Safety.OK:
            self._trip(w)
        assert w is not None  # None only with Safety.NAN, returned above
        if self._move.latched:
            return self._hold(t, Safety.OVER_LIMIT, self._move.latch_message)
        self._wrench = w
        return w

    def _check_ends(self, t: float, w: list[float], eef_pose: Matrix | None,
                    R_fixed_control: Matrix | None) -> CycleResult | None:
        """The move's end conditions this cycle: a lost or left path, an axis's force limit (after
        `force_limit_samples` wrenches over it) or max travel, a force jump."""
        axis, end = self._path.check(t, eef_pose, R_fixed_control, self._set, self._path_error,
                                     self._path_velocity)
        if not end:
            axis, end = self._ends.check(t, self._set, w, self._moved.values)
        return self._end_and_hold(t, axis, end) if end else None

    def _step_velocities(self, t: float, w: list[float], T_cs: Matrix | None, R_fc: Matrix | None) -> None:
        """Each active axis's law, then its velocity shaped by the rate limits over the cycle's dt."""
        dt = self._cycle_dt(t)
        c, v, tuning, travel = self._set, self._v, self._tuning, self._moved.values
        error, reference, fast = self._path_error, self._path_velocity, self.preprocessor.fast
        turn = self._normal.control_step(w, v, dt, T_cs, R_fc) if c.normal_axes else None
        for i in c.active:
            if c.is_path[i]:
                target = path_velocity(c.laws[i], tuning[i], w[i], error[i], reference[i])
            elif turn is not None and i in c.normal_axes:
                # with a path: its reference's turn fed forward (the surface as planned), the force the rest
                target = normal_velocity(c.laws[i], turn[i - 3]) + (reference[i] if c.path_axes else 0.0)
            else:
                target = law_velocity(c.laws[i], tuning[i], w[i], travel[i])
                if c.types[i] == Law.FORCE_TRACKING:
                    target = self._integral.velocity(i, c, tuning[i], target, w[i], fast[i], dt)
            v[i] = shape_velocity(target, v[i], tuning[i], dt, c.floor[i])

    def _cycle_dt(self, t: float) -> float:
        """Time since the last cycle that moved the axes (nominal after a hold), at most the stale timeout."""
        last, self._last_t = self._last_t, t
        return self._dt_nominal if last is None else min(max(t - last, 0.0), self.intake.wrench_timeout)

    def _watch_oscillation(self, t: float) -> CycleResult | None:
        """The watchdog (oscillation.OscillationGuard): an oscillating axis's gain is halved once (the move
        goes on); the second time the move ends (OSCILLATION, every axis holds)."""
        if self._watch is None:
            return None
        for i, lower, what in self._watch.check(t, self._v, self._set.watched, self._set.laws):
            if lower is None:
                self._end_move(i, End.OSCILLATION, False, what)
                return self._hold(t, Safety.OK, "")
            self._set = self._set.with_law(i, lower)
            self._watch_floor_update()
            self.notes.append(what)
        return None

    def check_stale(self, t: float) -> CycleResult | None:
        """Timer check: None while wrenches are fresh, else a zero-output result (Safety.STALE); ends the
        move with NO_FT_DATA once data has been missing for `no_data_end_timeout`."""
        last, timeout, move = self.intake.last_wrench_time, self.intake.wrench_timeout, self._move
        if last is not None and t - last <= timeout:
            return None
        if move.active:
            missing = move.without_data(t, last)
            if missing >= self._end_timeout:
                self._end_move(-1, End.NO_FT_DATA, False, f"no wrench for {missing:.3f} s")
        elif self._reaction.active and last is not None and t - last >= self._end_timeout:
            self._stop_reaction(f"no wrench for {t - last:.3f} s")
        age = "no wrench received yet" if last is None else f"no wrench for {t - last:.3f} s"
        if move.latched:  # the latch outranks staleness: it needs a reset, data alone will not clear it
            return self._hold(t, Safety.OVER_LIMIT, f"{move.latch_message}; {age}")
        return self._hold(t, Safety.STALE, f"{age} (wrench_timeout {timeout} s)")

    def hold(self, t: float, safety: int, message: str, received: bool = True) -> CycleResult:
        """Zero output for a reason found outside (SAFETY_NO_TF); the move resumes on the next update.
        `received`: a wrench came at `t` (so the stale check does not also fire)."""
        if received:
            self.intake.last_wrench_time = t
        return self._hold(t, safety, message)

    # --- internals ---
    def _result(self, t: float, safety: int, message: str) -> CycleResult:
        move = self._move
        if not message and not move.active:
            note = self._reaction.note
            message = f"{move.message}; {note}" if note else move.message
        result = CycleResult(t, list(self._v), self._wrench, list(self._moved.values), list(self._shown),
                             list(move.end), move.active, safety, message, move.ended_axis, move.id,
                             self._reaction.reacting(), list(self._set.actions))
        self.last_result = result
        return result

    def _hold(self, t: float, safety: int, message: str) -> CycleResult:
        self._v = [0.0] * 6
        self._last_t = None  # restart the rate limits from rest
        self._ends.held(t)
        return self._result(t, safety, message)

    def _watch_floor_update(self) -> None:
        """The watchdog's velocity floors follow the laws, the tuning and the measured noise."""
        if self._watch is not None:
            self._watch.set_floor(self._tuning, self._set.laws, self.intake.noise_floor)

    def _end_and_hold(self, t: float, axis: int, condition: int) -> CycleResult:
        why = end_reason(axis, condition, self._set.laws[axis], force=self._wrench[axis],
                         travel=self._moved.values[axis], path_error=self._path_error[axis],
                         path_age=self._path.age(t), path_timeout=self._path.timeout,
                         diff=self._ends.diff[axis])
        kept = self._v
        self._end_move(axis, condition, True, why)
        if condition == End.FT_VIOLATION and self._reaction.start(self._set.laws, self._wrench):
            for i in self._reaction.follower_axes():
                self._shown[i] = Law.FOLLOWER  # gravity compensation: what the axis runs now
        elif condition == End.MAX_TRAVEL and self._reaction.coast(kept, self.settings.end_stop_time):
            self._v = kept  # from this cycle's velocity to rest over end_stop_time (exceeded.py)
            return self._result(t, Safety.OK, "")
        return self._hold(t, Safety.OK, "")

    def _react(self, t: float, w: list[float]) -> CycleResult:
        """A cycle of the exceeded actions after the move ended (`exceeded.ExceededReaction`)."""
        self._reaction.step(w, self._v, self._cycle_dt(t))
        return self._result(t, Safety.OK, "")

    def _stop_reaction(self, reason: str) -> bool:
        """Ends the exceeded actions (stop, missing data); returns whether one ran."""
        if not self._reaction.active:
            return False
        self._reaction.clear()
        self._shown = list(self._set.types)
        self._v = [0.0] * 6
        self._move.message = f"{self._move.message}; exceeded action ended: {reason}"
        return True

    def _end_move(self, axis: int, condition: int, ok: bool, message: str) -> None:
        self._move.finish(axis, condition, ok, message, self._set.active)
        self._v = [0.0] * 6

    def _trip(self, w: list[float] | None) -> None:
        if w:
            self._wrench = w  # ~status and the events show the wrench that tripped
        self._reaction.clear()  # nothing moves after a safety trip, whatever the exceeded action said
        self._v = [0.0] * 6
        self._move.latch(self._global.message(w, self.preprocessor.max_force, self.preprocessor.max_torque))
        if self._move.active:
            self._end_move(-1, End.FT_VIOLATION, False, self._move.latch_message)
