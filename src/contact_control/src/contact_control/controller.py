"""ContactControl: wrench preprocessing plus the six axis laws, one `update` per wrench.

Decisions (the README repeats them):
- A move runs from `set_laws` until any active axis meets an end condition (force/torque limit, max travel,
  force jump), `stop()`, a new request, a global-limit trip or prolonged missing data; then every axis holds
  still (zero velocity) and the result says which axis and condition ended it.
- NaN/inf wrench: zero output in that same cycle (SAFETY_NAN); the move resumes with the next valid wrench.
- Stale wrench (none for `wrench_timeout`, or a header stamp older than that): zero output (SAFETY_STALE) from
  `check_stale`, which the node calls once the data is due to turn stale (`fresh_until`); after
  `no_data_end_timeout` the move ends (NO_FT_DATA).
- Wrench over `global_max_force`/`global_max_torque`: zero output, the move ends (FT_VIOLATION on its active
  axes) and the safety stays latched, refusing new laws, until `reset_safety()`.
- After any pause the velocity restarts from zero under the acceleration limit.
- A move that ended on a force/torque limit hands over to the axes' exceeded actions (`exceeded`): move away
  from the contact or gravity compensation. Twists keep coming while one runs (`CycleResult.commanding`).

Not thread-safe: the node serialises calls with one lock.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import NamedTuple

import numpy as np
from compliant_common.typedefs import FloatArray

from contact_control.axes import (
    AXES,
    END_DIFF_VIOLATION,
    END_EXTERNAL_STOP,
    END_FT_VIOLATION,
    END_MAX_TRAVEL,
    END_NAMES,
    END_NO_FT_DATA,
    END_NONE,
    END_OSCILLATION,
    END_PATH_ERROR,
    END_PATH_LOST,
    LAW_FOLLOWER,
    LAW_FORCE_TRACKING,
    LAW_NONE,
    LAW_PATH,
    LAW_SPRING,
    SAFETY_NAN,
    SAFETY_OK,
    SAFETY_OVER_LIMIT,
    SAFETY_STALE,
    SAFETY_ZEROING,
)
from contact_control.drift import ZeroDrift
from contact_control.exceeded import ExceededReaction
from contact_control.laws import (
    AxisLaw,
    ForceWindow,
    check_end,
    guard_pressing,
    law_velocity,
    path_velocity,
    shape_velocity,
)
from contact_control.loop_gain import GainBound
from contact_control.noise_floor import NoiseFloor
from contact_control.oscillation import OscillationWatch, halved
from contact_control.params import ContactControlSettings
from contact_control.path_ref import PathReference
from contact_control.preprocess import Matrix, PreprocessError, WrenchPreprocessor, as_rows, is_finite6
from contact_control.rate import SamplePeriod
from contact_control.request import FAILURE, SET_CONTROL_FORCE_FAILED, RequestError
from contact_control.travel import TravelMeter
from contact_control.zeroing import SteadyZero

__all__ = ["AxisState", "ContactControl", "CycleResult"]

_ZEROS = (0.0,) * 6
#: Filtered noise stds of force a velocity reversal must exceed to count for the watchdog (noise
#: crosses 3 stds about once in 20 independent samples: ~2 s of a 5 Hz filter's output).
WATCH_NOISE_SIGMAS = 3.0
_NO_TRAVEL = (LAW_FOLLOWER, LAW_FORCE_TRACKING)  # laws that need no travel unless they have a max travel



class AxisState(NamedTuple):
    """One axis of a cycle, as in compliant_control_msgs/AxisState."""

    axis: str
    law: int
    end_condition: int
    force: float
    velocity: float
    travel: float


class CycleResult:
    """The outcome of one cycle. Lists are fresh each cycle, so a result may be kept.

    Attributes:
        t: cycle time [s].
        velocity: commanded twist (vx, vy, vz [m/s], wx, wy, wz [rad/s]) in the control frame.
        wrench: preprocessed wrench in the control frame [N, Nm] (the last valid one while holding).
        travel: travel since the law was set [m, rad].
        laws: law type per axis.
        end_conditions: end condition per axis (non-zero on the axis that ended the move).
        move_active: laws set and no end condition met.
        safety: SAFETY_* code; message: why, in words ('' when all is well).
        ended_axis: index of the axis that ended the move, -1 if none or not a single axis.
        move_id: counts `set_laws` calls.
        reacting: per axis, carrying out its exceeded action after the move ended (moving away, following).
        actions: per axis, the exceeded action (EXCEEDED_*) of its law; -1 on axes without a force limit.
    """

    __slots__ = (
        "actions",
        "end_conditions",
        "ended_axis",
        "laws",
        "message",
        "move_active",
        "move_id",
        "reacting",
        "safety",
        "t",
        "travel",
        "velocity",
        "wrench",
    )

    def __init__(
        self,
        t: float,
        velocity: list[float],
        wrench: list[float],
        travel: list[float],
        laws: list[int],
        end_conditions: list[int],
        move_active: bool,
        safety: int,
        message: str,
        ended_axis: int,
        move_id: int,
        reacting: list[bool] | None = None,
        actions: list[int] | None = None,
    ) -> None:
        self.t = t
        self.velocity = velocity
        self.wrench = wrench
        self.travel = travel
        self.laws = laws
        self.end_conditions = end_conditions
        self.move_active = move_active
        self.safety = safety
        self.message = message
        self.ended_axis = ended_axis
        self.move_id = move_id
        self.reacting = reacting if reacting is not None else [False] * 6
        self.actions = actions if actions is not None else [-1] * 6

    @property
    def commanding(self) -> bool:
        """Twists are due: a move runs, or an axis carries out its exceeded action after it."""
        return self.move_active or any(self.reacting)

    @property
    def twist(self) -> FloatArray:
        """The commanded twist as a numpy array (6,), control frame."""
        return np.array(self.velocity)

    @property
    def axes(self) -> list[AxisState]:
        return [
            AxisState(
                AXES[i],
                self.laws[i],
                self.end_conditions[i],
                self.wrench[i],
                self.velocity[i],
                self.travel[i],
            )
            for i in range(6)
        ]

    def __repr__(self) -> str:
        return (
            f"CycleResult(t={self.t}, velocity={self.velocity}, safety={self.safety}, "
            f"move_active={self.move_active}, message={self.message!r})"
        )


class ContactControl:
    """Preprocessing and the six axis laws; see the module docstring for the stop/resume rules."""

    def __init__(self, settings: ContactControlSettings | None = None) -> None:
        s = settings or ContactControlSettings()
        self.settings = s
        self.preprocessor = WrenchPreprocessor(s)
        self._tuning = tuple(s.tuning(i >= 3) for i in range(6))
        self._timeout = s.wrench_timeout
        self._rate = SamplePeriod()
        self._adapt_filter = s.lp_filter_rate_adapt and s.lp_filter_enabled
        self.notes: list[str] = []  # what the node should log once (the sensor's measured rate, ...)
        self._end_timeout = s.no_data_end_timeout
        self._check_age = s.check_stamp_age
        self._future = s.future_stamp_tolerance
        self._dt_nominal = 1.0 / s.control_rate
        self._diff = tuple(t.diff_max for t in self._tuning)
        self._windows = [ForceWindow(s.diff_window) for _ in range(6)]
        # The tool's own inertia while the axes speed up from rest reads as force on a wrist sensor (1 kg
        # at 0.5 m/s^2 is 0.5 N), so force limits are checked from force_limit_arm_time after a start.
        self._arm_time = s.force_limit_arm_time
        self._armed = [True] * 6
        self._from_rest: float | None = None  # when the axes last started from rest
        self._meter = TravelMeter(s.travel_directions)
        self._travel_offset = [0.0] * 6  # travel of an axis whose law changed during a move, at the change
        self._reaction = ExceededReaction(self._tuning, s.move_away_release_fraction)
        self._actions = [-1] * 6  # per axis: EXCEEDED_* of its law, -1 without a force limit
        self._laws: list[AxisLaw] = [AxisLaw()] * 6
        self._law_types = [LAW_NONE] * 6
        self._active: tuple[int, ...] = ()
        self._diff_axes: tuple[int, ...] = ()
        self._needs_travel = False
        self._floor = [True] * 6  # per axis: zero commands below min velocity (not for force tracking, path)
        self._guarded = [False] * 6  # per axis: force tracking with the pressing guard (fast_guard)
        self._path = PathReference(s.path_reference_timeout, s.path_extrapolate)
        self._path_axes: tuple[int, ...] = ()
        self._is_path = [False] * 6
        self._watched: tuple[int, ...] = ()  # the oscillation watchdog's axes (not a path: it may turn)
        self._path_error = [0.0] * 6
        self._path_velocity = [0.0] * 6
        self._v = [0.0] * 6
        self._travel = [0.0] * 6
        self._wrench = [0.0] * 6
        self._end = [END_NONE] * 6
        self._ended_axis = -1
        self._move_active = False
        self._move_id = 0
        self._move_t0: float | None = None
        self._end_ok = True
        self._end_message = "no move yet"
        self._outcomes: dict[int, bool] = {}
        self._latched = False
        self._latch_message = ""
        self._last_rx: float | None = None
        self._last_t: float | None = None
        self._tare_pending = s.tare_on_startup
        self._zeroing = self._new_zeroing() if s.tare_on_startup else None
        self._floor_noise: NoiseFloor | None = None
        #: How far the offset moves over the workspace beyond the noise (force [N], torque [Nm]): a bias
        #: map's held-out residual, else the declared pose_offset_force / _torque.
        self.pose_residual = (s.pose_offset_force, s.pose_offset_torque)
        self._gain_bound = GainBound(s.loop_gain_delay, s.command_latency, s.spring_output_scale,
                                     s.contact_stiffness)
        self._limit_samples = int(s.force_limit_samples)
        self._over = [0] * 6  # per axis: wrenches in a row over its force limit
        self._over_global = 0  # wrenches in a row over a global limit
        self._watch_floor = [t.min_velocity for t in self._tuning]
        self._watch = (OscillationWatch(int(s.oscillation_reversals), s.oscillation_window)
                       if s.oscillation_reversals > 0 else None)
        self._halved = [False] * 6  # per axis: the watchdog has halved its gain in this move
        self._requested: list[AxisLaw] = []  # the laws as last requested (the watchdog may lower them)
        self._drift = (ZeroDrift(s.drift_window, s.tare_max_force_spread, s.tare_max_torque_spread,
                                 s.tare_spread_sigmas)
                       if s.drift_window > 0.0 else None)
        self._drift_next = 0.0  # when the drift watch takes its next sample [s]
        self._last_raw: Sequence[float] | None = None
        self._last_R: Matrix | None = None
        self.last_result = self._result(0.0, SAFETY_STALE, "no wrench yet")

    # --- state ---
    @property
    def move_active(self) -> bool:
        return self._move_active

    @property
    def move_id(self) -> int:
        return self._move_id

    def reacting(self) -> list[bool]:
        """Per axis, carrying out its exceeded action now (`last_result.reacting` is the last cycle's)."""
        return self._reaction.reacting()

    @property
    def end_ok(self) -> bool:
        """Whether the last move ended by an axis end condition (force limit, max travel, force jump)."""
        return self._end_ok

    def move_outcome(self, move_id: int) -> bool | None:
        """None while move `move_id` runs; then whether it ended by an axis end condition (see `end_ok`)."""
        if move_id == self._move_id and (self._move_active or self._reaction.moving_away):
            return None  # a blocking caller hears of the end once the press is released
        return self._outcomes.get(move_id, False)

    @property
    def end_message(self) -> str:
        return self._end_message

    @property
    def laws(self) -> tuple[AxisLaw, ...]:
        return tuple(self._laws)

    @property
    def needs_travel(self) -> bool:
        """Whether the running move uses travel (spring, compliant move, max travel): needs EEF poses."""
        return self._move_active and self._needs_travel

    @property
    def zeroing(self) -> bool:
        """Whether start-up zeroing has not finished yet (laws hold still until it has)."""
        return self._tare_pending

    @property
    def noise_floor(self) -> NoiseFloor | None:
        """The sensor's noise at rest, measured while zeroing at start-up (None before, or if not zeroed)."""
        return self._floor_noise

    def resolvable(self) -> tuple[float, float]:
        """The smallest force [N] and torque [Nm] limits a request may set (0, 0: unknown or unchecked)."""
        sigmas = self.settings.noise_limit_sigmas
        if self._floor_noise is None or sigmas <= 0.0:
            return 0.0, 0.0
        force, torque = self._floor_noise.resolvable(sigmas)
        pose_force, pose_torque = self.pose_residual
        return math.hypot(force, sigmas * pose_force), math.hypot(torque, sigmas * pose_torque)

    def bound_gains(self, laws: Sequence[AxisLaw]) -> tuple[list[AxisLaw], list[str]]:
        """The laws with their loop gains within what the sensor's measured rate (`lp_filter_delta_t` until
        measured) and the command latency keep stable, and a note per lowered gain (see `loop_gain`)."""
        period = self._rate.period or self.settings.lp_filter_delta_t
        cutoff = self.preprocessor.cutoff if self.settings.lp_filter_enabled else None
        return self._gain_bound.limit(laws, period, cutoff)

    def check_resolvable(self, laws: Sequence[AxisLaw]) -> None:
        """Refuses limits the sensor cannot tell from its noise.

        Raises:
            RequestError: SET_CONTROL_FORCE_FAILED naming the axis, the limit and the noise floor.
        """
        floor = self._floor_noise
        if floor is None:
            return
        force, torque = self.resolvable()
        for i, law in enumerate(laws):
            least = torque if i >= 3 else force
            if law.law and 0.0 < law.force_limit < least:
                unit, what = ("Nm", "torque") if i >= 3 else ("N", "force")
                std = floor.torque if i >= 3 else floor.force
                pose = self.pose_residual[1 if i >= 3 else 0]
                moving = (f" and the offset's change with the pose {pose:.3g} {unit} (the bias map's "
                          "held-out residual, or pose_offset_force / _torque)") if pose > 0.0 else ""
                raise RequestError(
                    SET_CONTROL_FORCE_FAILED,
                    f"axis {AXES[i]}: {what} limit {law.force_limit:g} {unit} is below what the sensor "
                    f"resolves, {least:.3g} {unit} ({self.settings.noise_limit_sigmas:g} x its filtered "
                    f"noise {std:.3g} {unit}, measured at rest while zeroing{moving}; noise_limit_sigmas): "
                    f"set a limit of at least {least:.3g} {unit}",
                    AXES[i],
                )

    @property
    def safety_latched(self) -> bool:
        return self._latched

    # --- commands ---
    def set_laws(
        self,
        laws: Sequence[AxisLaw],
        eef_pose: Matrix | None = None,
        t: float | None = None,
        R_fixed_control: Matrix | None = None,
    ) -> int:
        """Starts a move with six laws (x, y, z, rx, ry, rz), replacing any running move at once.

        Args:
            laws: validated laws (see `request.validate_request`).
            eef_pose: 4x4 EEF pose in the fixed frame at the start; None: taken from the next `update`.
            t: current time [s] (for the no-data end timeout).
            R_fixed_control: control frame orientation at the start (3x3); None: the fixed frame's.

        Returns:
            The new move id.

        Raises:
            RequestError: the global safety is latched (reset first); nothing changes.
            ValueError: not six AxisLaw; nothing changes.
        """
        laws = list(laws)
        if len(laws) != 6 or not all(isinstance(law, AxisLaw) for law in laws):
            raise ValueError("set_laws needs six AxisLaw (x, y, z, rx, ry, rz)")
        if self._latched:
            raise RequestError(FAILURE, f"safety latched ({self._latch_message}); call reset first")
        self.check_resolvable(laws)
        if self._move_active and laws == self._requested:
            return self._move_id  # a re-sent request (GUI Apply held, a script in a loop): nothing changes
        self._requested = laws
        if self._drift is not None:
            self._drift.restart()
        self._over = [0] * 6
        self._halved = [False] * 6
        if self._watch is not None:
            self._watch.clear()
        if self._move_active and any(law.law for law in laws):
            return self._change_laws(laws, t)
        if self._move_active:
            self._end_move(-1, END_EXTERNAL_STOP, False, "replaced by a new request")
        self._travel_offset = [0.0] * 6
        self._reaction.clear()
        self._adopt(laws)
        for window in self._windows:
            window.clear()
        self._v = [0.0] * 6
        self._armed = [self._arm_time <= 0.0] * 6
        self._from_rest = t
        self._travel = [0.0] * 6
        self._end = [END_NONE] * 6
        self._ended_axis = -1
        self._move_id += 1
        self._move_t0 = t
        self._last_t = None
        self._meter.clear()
        if eef_pose is not None:
            self._meter.start(eef_pose, R_fixed_control)
        self._move_active = bool(self._active)
        self._end_ok = True
        self._end_message = "" if self._active else "no laws set"
        if not self._active:
            self._outcomes[self._move_id] = True
        return self._move_id

    def _adopt(self, laws: list[AxisLaw]) -> None:
        """What the cycle needs to know of six laws (a new move's or a changed one's)."""
        self._laws = laws
        self._law_types = [law.law for law in laws]
        self._actions = [law.exceeded_action if law.law and law.force_limit > 0.0 else -1 for law in laws]
        self._active = tuple(i for i in range(6) if laws[i].law != LAW_NONE)
        self._diff_axes = tuple(i for i in self._active if self._diff[i] > 0.0)
        self._needs_travel = any(law.law not in _NO_TRAVEL or law.max_travel > 0.0 for law in laws if law.law)
        self._floor = [law.law not in (LAW_FORCE_TRACKING, LAW_PATH) for law in laws]
        self._guarded = [self.settings.force_tracking_fast_guard and law.law == LAW_FORCE_TRACKING
                         and law.target != 0.0 for law in laws]
        self.preprocessor.keep_fast = any(self._guarded)
        self._is_path = [law.law == LAW_PATH for law in laws]
        self._path_axes = tuple(i for i in self._active if self._is_path[i])
        self._watched = tuple(i for i in self._active if not self._is_path[i])
        self._watch_floor_update()

    def _change_laws(self, laws: list[AxisLaw], t: float | None) -> int:
        """Bumpless re-configuration of a running move: an axis that keeps its law type keeps its velocity,
        travel and force-limit arming (new parameters apply from its current state, within the rate limits);
        an axis whose law changes starts from rest, its travel from here. The move gets a new id (a blocking
        caller of the old request is answered), but nothing stops."""
        old, kept = self._law_types, list(self._v)
        self._end_move(-1, END_EXTERNAL_STOP, False, "changed by a new request")
        self._v = kept
        for i, law in enumerate(laws):
            if law.law != old[i] or not law.law:
                self._v[i] = 0.0
                self._travel_offset[i] = self._travel[i] + self._travel_offset[i]
                self._travel[i] = 0.0
                self._windows[i].clear()
                self._armed[i] = self._arm_time <= 0.0
        if not all(self._armed):
            self._from_rest = t
        self._adopt(laws)
        self._end = [END_NONE] * 6
        self._ended_axis = -1
        self._move_id += 1
        self._move_active = True
        self._end_ok = True
        self._end_message = ""
        return self._move_id

    @property
    def sample_period(self) -> float | None:
        """The sensor's measured sample period [s] (None until measured)."""
        return self._rate.period

    @property
    def last_wrench_time(self) -> float | None:
        """When the newest valid wrench arrived [s] (None: none yet, or since a reset of the timing)."""
        return self._last_rx

    @property
    def wrench_timeout(self) -> float:
        """The stale timeout in use [s]: wrench_timeout, or wrench_timeout_periods periods if longer."""
        return self._timeout

    def _on_sample_period(self, period: float) -> None:
        """Keeps the filter's cutoff (in Hz) and the stale timeout true to the sensor's measured rate."""
        s = self.settings
        if s.wrench_timeout_periods > 0.0:
            self._timeout = max(s.wrench_timeout, s.wrench_timeout_periods * period)
        pre = self.preprocessor
        if self._adapt_filter and abs(period - pre.design_period) > 0.1 * pre.design_period:
            cutoff = pre.redesign_filter(period)
            rate = 1.0 / period
            note = f"low-pass filter designed for the measured {rate:.4g} Hz wrench (cutoff {cutoff:.3g}"
            configured = s.lp_filter_delta_t
            if abs(period - configured) > 0.2 * configured:
                note += f" Hz; lp_filter_delta_t says {configured} s, {1.0 / configured:.4g}"
            note += " Hz"
            self.notes.append(f"{note}); stale after {self._timeout:.3g} s")

    def set_path_reference(self, position: Sequence[float], quaternion: Sequence[float],
                           twist: Sequence[float], t: float) -> str:
        """The path law's reference at time `t` [s] (fixed frame; see `path_ref.PathReference.set`): '' or why
        it is refused."""
        return self._path.set(position, quaternion, twist, t)

    def clock_jumped(self, t: float, description: str) -> CycleResult:
        """The clock jumped (see compliant_common.clock): every duration measured across it is wrong, so the
        output halts and the timing restarts at `t` (no wrench counts as received, the no-data end timeout and
        force-limit arming restart); the move resumes with the next wrench stamped after the jump."""
        self._last_rx = None
        self._last_t = None
        self._rate.reset()
        if self._move_active:
            self._move_t0 = t
        for window in self._windows:
            window.clear()
        return self._hold(t, SAFETY_STALE, f"{description}: timing reset, holding until fresh data")

    def stop(self, reason: str = "stop requested") -> bool:
        """Ends the running move (EXTERNAL_STOP) or exceeded action; returns whether one was running."""
        if not self._move_active:
            return self._stop_reaction(reason)
        self._end_move(-1, END_EXTERNAL_STOP, False, reason)
        return True

    def tare(
        self, wrench: Sequence[float] | None = None, R_world_sensor: Matrix | None = None
    ) -> tuple[float, ...]:
        """Zeroes the sensor at the current (or given) reading; see `WrenchPreprocessor.tare`.

        Raises:
            PreprocessError: no valid wrench to tare with; the bias is unchanged.
        """
        if wrench is None:
            if self._last_raw is None:
                raise PreprocessError("no wrench received yet")
            wrench, R_world_sensor = self._last_raw, self._last_R
        bias = self.preprocessor.tare(wrench, R_world_sensor)
        self._tare_pending = False
        if self._drift is not None:  # the zero is here now
            self._drift.rezeroed()
        return bias

    @property
    def last_raw(self) -> Sequence[float] | None:
        """The last wrench received (sensor frame, as sent), None before the first."""
        return self._last_raw

    def start_zeroing(self) -> None:
        """Zeroes the sensor again over a steady window from the next wrench, as at start-up, and measures
        the noise floor again (`tare_window` 0: on the next wrench alone). The laws hold still until it is
        done (`zeroing`); the bias in use stays until then."""
        self._zeroing = self._new_zeroing()
        self._tare_pending = True

    def cancel_zeroing(self) -> str:
        """Gives up a zeroing that has not finished: the bias stays as it was. Returns why it was waiting."""
        note = self._zeroing.note if self._zeroing is not None else "no valid wrench"
        self._tare_pending = False
        return note

    def _new_zeroing(self) -> SteadyZero | None:
        s = self.settings
        if s.tare_window <= 0.0:
            return None
        return SteadyZero(s.tare_window, s.tare_max_force_spread, s.tare_max_torque_spread,
                          int(s.tare_min_samples), s.tare_spread_sigmas)

    def reset_safety(self) -> bool:
        """Clears a latched global-limit trip; returns whether it was latched."""
        was = self._latched
        self._latched = False
        self._latch_message = ""
        return was

    # --- cycles ---
    def update(
        self,
        wrench: Sequence[float],
        t: float,
        T_control_sensor: Matrix | None = None,
        R_world_sensor: Matrix | None = None,
        eef_pose: Matrix | None = None,
        R_fixed_control: Matrix | None = None,
        stamp: float | None = None,
    ) -> CycleResult:
        """One control cycle for a received wrench.

        Args:
            wrench: (fx, fy, fz, tx, ty, tz) [N, Nm] in the sensor frame.
            t: receive time [s], same clock as every other call.
            T_control_sensor: 4x4 sensor pose in the control frame; None: same frame.
            R_world_sensor: 3x3 sensor orientation in the fixed frame (for tool gravity).
            eef_pose: 4x4 EEF pose in the fixed frame (for travel); None: travel not updated.
            R_fixed_control: control frame orientation at the move's start, used if the start is taken now.
            stamp: the wrench's header time [s] or None; older than wrench_timeout counts as no data.
        """
        if self._rate.add(t if stamp is None else stamp):
            self._on_sample_period(self._rate.period)  # type: ignore[arg-type]
        if stamp is not None and self._check_age:
            if t - stamp > self._timeout:
                age = f"wrench stamp is {t - stamp:.3f} s old (wrench_timeout {self._timeout} s)"
                return self._hold(t, SAFETY_STALE, age)
            if stamp - t > self._future:  # another clock, or data from before a backward clock jump
                self._last_rx = t
                ahead = f"wrench stamped {stamp - t:.3f} s ahead (future_stamp_tolerance {self._future} s)"
                return self._hold(t, SAFETY_NAN, f"{ahead}: holding until data stamped by this node's clock")
        self._last_rx = t
        self._last_raw, self._last_R = wrench, R_world_sensor
        if self._tare_pending and is_finite6(wrench):
            zeroing = self._zeroing
            if zeroing is None:
                self.preprocessor.tare(wrench, R_world_sensor)
            else:
                bias = zeroing.add(self.preprocessor.bias_estimate(wrench, R_world_sensor), t)
                if bias is None:
                    return self._hold(t, SAFETY_ZEROING, zeroing.note)
                self.preprocessor.set_bias(bias, at_rest=True)
                self.notes.append(
                    f"sensor zeroed over {zeroing.duration:.3g} s: bias "
                    f"[{', '.join(f'{b:.3g}' for b in bias)}] (N, Nm, sensor frame, tool weight out)"
                )
                self._measured_floor(zeroing)
            self._tare_pending = False
            if self._drift is not None:  # a new window from the new zero; a drift measured before is 0 now
                if self._drift.drift is None:
                    self._drift.restart()
                else:
                    self._drift.rezeroed()
        code, w = self.preprocessor.process(wrench, T_control_sensor, R_world_sensor)
        if code != SAFETY_OK:
            if code == SAFETY_NAN:
                return self._hold(t, SAFETY_NAN, "wrench contains NaN or inf: holding until valid data")
            self._over_global += 1
            if self._over_global < self._limit_samples and not self._latched:
                # A spike unless the next wrench is over too (force_limit_samples): a 15 N push on a 3.6 N
                # current estimate crossed 25 N on single samples. The last command stands meanwhile.
                return self._result(t, SAFETY_OK, "")
            self._trip(w)
        else:
            self._over_global = 0
        assert w is not None  # None only with SAFETY_NAN, returned above
        if self._latched:
            return self._hold(t, SAFETY_OVER_LIMIT, self._latch_message)
        self._wrench = w
        if not self._move_active:
            if self._reaction.active:
                return self._react(t, w)
            if self._drift is not None and t >= self._drift_next:
                self._drift_next = t + 0.02
                self._watch_drift(wrench, R_world_sensor, t)
            return self._result(t, SAFETY_OK, "")
        travel = self._travel
        if eef_pose is not None:
            if not self._meter.started:
                self._meter.start(eef_pose, R_fixed_control)
            self._meter.measure(eef_pose, travel)
            offset = self._travel_offset
            if any(offset):
                for i in range(6):
                    travel[i] -= offset[i]
        laws = self._laws
        armed = self._armed
        over = self._over
        is_path, error = self._is_path, self._path_error
        if self._path_axes:
            if eef_pose is None or not self._path.error(t, eef_pose, R_fixed_control, error,
                                                       self._path_velocity):
                return self._end_and_hold(t, self._path_axes[0], END_PATH_LOST)
            for i in self._path_axes:
                if 0.0 < laws[i].max_travel <= abs(error[i]):
                    return self._end_and_hold(t, i, END_PATH_ERROR)
        for i in self._active:
            end = check_end(laws[i], w[i] if armed[i] else 0.0, 0.0 if is_path[i] else travel[i])
            if end == END_FT_VIOLATION:
                over[i] += 1
                if over[i] < self._limit_samples:  # one spike over the limit is not a contact
                    end = check_end(laws[i], 0.0, 0.0 if is_path[i] else travel[i])
            elif over[i]:
                over[i] = 0
            if end:
                return self._end_and_hold(t, i, end)
        for i in self._diff_axes:
            if self._windows[i].add(t, w[i]) > self._diff[i]:
                return self._end_and_hold(t, i, END_DIFF_VIOLATION)
        last = self._last_t
        dt = self._dt_nominal if last is None else min(max(t - last, 0.0), self._timeout)
        self._last_t = t
        v, tuning, floor = self._v, self._tuning, self._floor
        guarded, fast = self._guarded, self.preprocessor.fast
        for i in self._active:
            if is_path[i]:
                target = path_velocity(laws[i], tuning[i], w[i], error[i], self._path_velocity[i])
            else:
                target = law_velocity(laws[i], tuning[i], w[i], travel[i])
                if guarded[i]:
                    target = guard_pressing(laws[i], tuning[i], target, fast[i])
            v[i] = shape_velocity(target, v[i], tuning[i], dt, floor[i])
        watch = self._watch
        if watch is not None:
            for i in self._watched:
                if watch.add(i, t, v[i], self._watch_floor[i]):
                    stopped = self._oscillating(t, i)
                    if stopped is not None:
                        return stopped
        if not all(armed):
            if self._from_rest is None:
                self._from_rest = t
            if t - self._from_rest >= self._arm_time:
                self._armed = [True] * 6
        return self._result(t, SAFETY_OK, "")

    def _measured_floor(self, zeroing: SteadyZero) -> None:
        """The noise floor of the zeroing window; the deadbands grow to `noise_deadband_sigmas` of it."""
        s = self.settings
        n = zeroing.count
        period = self._rate.period
        rate = 1.0 / period if period else (n - 1) / zeroing.duration if zeroing.duration > 0.0 else 0.0
        if n < 2 or rate <= 0.0:
            return
        cutoff = self.preprocessor.cutoff if s.lp_filter_enabled else None
        floor = NoiseFloor.measure(zeroing.std(), rate, n, cutoff, zeroing.lag1())
        self._floor_noise = floor
        self._watch_floor_update()
        if self._drift is not None:  # steady at rest now means within this noise (from the next window)
            self._drift.noise = floor.std
        note = floor.describe()
        k = s.noise_deadband_sigmas
        if k > 0.0:
            force_db = max(s.force_deadband, k * floor.force)
            torque_db = max(s.torque_deadband, k * floor.torque)
            self.preprocessor.set_deadband(force_db, torque_db)
            note += f"; deadbands {force_db:.3g} N, {torque_db:.3g} Nm ({k:g} filtered stds or as set)"
        force, torque = self.resolvable()
        if force > 0.0:
            note += f"; force limits below {force:.3g} N, torque limits below {torque:.3g} Nm are refused"
        self.notes.append(note)

    def contact_force(
        self,
        wrench: Sequence[float],
        T_control_sensor: Matrix | None = None,
        R_world_sensor: Matrix | None = None,
    ) -> tuple[float, float, float] | None:
        """The contact force of a raw wrench, unfiltered: sign flips, bias and tool weight out, in the control
        frame [N]; None for a NaN/inf wrench or a missing orientation. For guards that must see a contact as
        early as possible (jog_arm's contact guard): the low-pass filter of the laws lags it by tens of ms.
        It reads the current bias and tool model and changes nothing (no filter step, no limit check).
        """
        if len(wrench) != 6:
            return None
        f = self.preprocessor.contact_force(wrench, R_world_sensor)
        if f is None or T_control_sensor is None:
            return f
        r0, r1, r2 = as_rows(T_control_sensor)[:3]
        fx, fy, fz = f
        return (
            r0[0] * fx + r0[1] * fy + r0[2] * fz,
            r1[0] * fx + r1[1] * fy + r1[2] * fz,
            r2[0] * fx + r2[1] * fy + r2[2] * fz,
        )

    @property
    def fresh_until(self) -> float:
        """Time [s] until which the newest wrench counts as fresh (-inf before the first one)."""
        return -math.inf if self._last_rx is None else self._last_rx + self._timeout

    def check_stale(self, t: float) -> CycleResult | None:
        """Timer check: None while wrenches are fresh, else a zero-output result (SAFETY_STALE).

        Ends the move with NO_FT_DATA once data has been missing for `no_data_end_timeout`.
        """
        last = self._last_rx
        if last is not None and t - last <= self._timeout:
            return None
        if self._move_active and not self._move_t0 and t > 0.0:
            # Set under sim time before the clock ran (a law set before `rosbag play --clock`): the move's
            # wait for data starts with the clock, or it would end the moment the bag's clock appears.
            self._move_t0 = t
        if self._move_active:
            since = last if last is not None else self._move_t0
            if self._move_t0 is not None and (since is None or since < self._move_t0):
                since = self._move_t0
            if since is not None and t - since >= self._end_timeout:
                self._end_move(-1, END_NO_FT_DATA, False, f"no wrench for {t - since:.3f} s")
        elif self._reaction.active and last is not None and t - last >= self._end_timeout:
            self._stop_reaction(f"no wrench for {t - last:.3f} s")
        age = "no wrench received yet" if last is None else f"no wrench for {t - last:.3f} s"
        if self._latched:  # the latch outranks staleness: it needs a reset, data alone will not clear it
            return self._hold(t, SAFETY_OVER_LIMIT, f"{self._latch_message}; {age}")
        return self._hold(t, SAFETY_STALE, f"{age} (wrench_timeout {self._timeout} s)")

    def hold(self, t: float, safety: int, message: str, received: bool = True) -> CycleResult:
        """Zero output for a reason found outside (e.g. SAFETY_NO_TF); the move resumes on the next update.

        Args:
            received: a wrench did arrive at `t` (so the stale check does not also fire).
        """
        if received:
            self._last_rx = t
        return self._hold(t, safety, message)

    # --- internals ---
    def _result(self, t: float, safety: int, message: str) -> CycleResult:
        if not message and not self._move_active:
            note = self._reaction.note
            message = f"{self._end_message}; {note}" if note else self._end_message
        result = CycleResult(
            t,
            list(self._v),
            self._wrench,
            list(self._travel),
            list(self._law_types),
            list(self._end),
            self._move_active,
            safety,
            message,
            self._ended_axis,
            self._move_id,
            self._reaction.reacting(),
            self._actions,
        )
        self.last_result = result
        return result

    def _hold(self, t: float, safety: int, message: str) -> CycleResult:
        self._v = [0.0] * 6
        self._last_t = None  # restart the rate limits from rest
        if self._arm_time > 0.0:  # stopped at once: the speed-up that follows is a new start
            self._armed = [False] * 6
            self._from_rest = t
        return self._result(t, safety, message)

    @property
    def zero_drift(self) -> tuple[float, ...] | None:
        """How far the zero has moved since the bias was set, measured at rest [N, Nm], sensor frame (None:
        not yet measured)."""
        return None if self._drift is None else self._drift.drift

    def _watch_drift(self, wrench: Sequence[float], R_world_sensor: Matrix | None, t: float) -> None:
        """A sample at rest for the drift watch; re-tares when the policy says so."""
        assert self._drift is not None
        try:
            estimate = self.preprocessor.bias_estimate(wrench, R_world_sensor)
        except PreprocessError:  # no orientation for the tool's weight: no estimate
            return
        bias = self.preprocessor.bias
        drift = self._drift.add(estimate, bias, t)
        limit = self.settings.auto_tare_drift
        if drift is None or limit <= 0.0 or self._drift.force <= limit:
            return
        moved = self._drift.force
        self.preprocessor.set_bias([b + d for b, d in zip(bias, drift, strict=True)], at_rest=True)
        self._drift.rezeroed()
        self.notes.append(f"re-tared at rest: the zero had moved by {moved:.3g} N (auto_tare_drift "
                          f"{limit:g} N)")

    def retune(self, s: ContactControlSettings) -> list[str]:
        """Live tuning (params.TUNABLE): new limits, deadbands, filter cutoff and global limits from checked
        settings, applied bumplessly: the velocity commanded last stays, and the next cycles reach the new
        clamp within the acceleration and deceleration limits; the filter continues from its last output.
        Returns what changed, in words."""
        old, self.settings = self.settings, s
        self._tuning = tuple(s.tuning(i >= 3) for i in range(6))
        self._diff = tuple(t.diff_max for t in self._tuning)
        self._reaction.retune(self._tuning)
        self._watch_floor_update()
        changed = []
        if (s.global_max_force, s.global_max_torque) != (old.global_max_force, old.global_max_torque):
            self.preprocessor.set_limits(s.global_max_force, s.global_max_torque)
            changed.append(f"global limits {s.global_max_force:g} N, {s.global_max_torque:g} Nm")
        if s.lp_filter_cutoff_freq != old.lp_filter_cutoff_freq:
            used = self.preprocessor.set_cutoff(s.lp_filter_cutoff_freq)
            changed.append("no filter" if used is None else f"filter cutoff {used:.3g} Hz")
        return changed

    def _watch_floor_update(self) -> None:
        """The watchdog's velocity floor per axis: the minimum velocity, or the swing the sensor's noise
        alone gives a law (WATCH_NOISE_SIGMAS filtered stds / b) when larger: held against a push, a law's
        force error crosses zero with the noise and a 3.6 N estimate reversed a spring's velocity 6 times in
        2 s with nothing oscillating."""
        floor = self._floor_noise
        self._watch_floor = [t.min_velocity for t in self._tuning]
        if floor is None:
            return
        for i, law in enumerate(self._laws):
            if law.law != LAW_NONE and law.damping > 0.0:
                noise = floor.force if i < 3 else floor.torque
                self._watch_floor[i] = max(self._watch_floor[i], WATCH_NOISE_SIGMAS * noise / law.damping)

    def _oscillating(self, t: float, axis: int) -> CycleResult | None:
        """The watchdog saw `axis` oscillate: its gain is halved the first time (the move goes on), the move
        ends (OSCILLATION, every axis holds) the second."""
        assert self._watch is not None
        law, name = self._laws[axis], AXES[axis]
        what = (f"axis {name}: its velocity reversed {self._watch.reversals} times within "
                f"{self._watch.window:g} s (oscillation_reversals)")
        lower = None if self._halved[axis] else halved(law)
        self._watch.clear(axis)
        if lower is None:
            self._end_move(axis, END_OSCILLATION, False, f"{what}: stopped, the gain was already lowered")
            return self._hold(t, SAFETY_OK, "")
        laws = list(self._laws)
        laws[axis] = lower
        self._laws = laws
        self._halved[axis] = True
        self._watch_floor_update()
        k = f", k {law.stiffness:g} -> {lower.stiffness:g}" if law.law == LAW_SPRING else ""
        self.notes.append(f"{what}: gain halved (b {law.damping:g} -> {lower.damping:g}{k})")
        return None

    def _end_and_hold(self, t: float, axis: int, condition: int) -> CycleResult:
        law, name = self._laws[axis], AXES[axis]
        if condition == END_FT_VIOLATION:
            why = f"|{self._wrench[axis]:.3g}| reached the limit {law.force_limit}"
        elif condition == END_PATH_LOST:
            age = self._path.age(t)
            why = ("no ~path_reference received" if age == math.inf else
                   f"no ~path_reference for {age:.2f} s (path_reference_timeout {self._path.timeout:g} s)")
        elif condition == END_PATH_ERROR:
            unit = "rad" if axis >= 3 else "m"
            why = f"|{self._path_error[axis]:.4g}| {unit} from the path reached max_travel {law.max_travel:g}"
        elif condition == END_MAX_TRAVEL:
            why = f"travel |{self._travel[axis]:.4g}| reached the max path deviation {law.max_travel}"
        else:
            why = f"force changed by more than {self._diff[axis]} within the window"
        kept = self._v
        self._end_move(axis, condition, True, f"axis {name}: {END_NAMES[condition]}: {why}")
        if condition == END_FT_VIOLATION and self._reaction.start(self._laws, self._wrench):
            for i in self._reaction.follower_axes():
                self._law_types[i] = LAW_FOLLOWER  # gravity compensation: what the axis runs now
        elif condition == END_MAX_TRAVEL and self._reaction.coast(kept, self.settings.end_stop_time):
            self._v = kept  # from this cycle's velocity to rest over end_stop_time (exceeded.py)
            return self._result(t, SAFETY_OK, "")
        return self._hold(t, SAFETY_OK, "")

    def _react(self, t: float, w: list[float]) -> CycleResult:
        """A cycle of the exceeded actions after the move ended (`exceeded.ExceededReaction`)."""
        last = self._last_t
        dt = self._dt_nominal if last is None else min(max(t - last, 0.0), self._timeout)
        self._last_t = t
        self._reaction.step(w, self._v, dt)
        return self._result(t, SAFETY_OK, "")

    def _stop_reaction(self, reason: str) -> bool:
        """Ends the exceeded actions (stop, missing data); returns whether one ran."""
        if not self._reaction.active:
            return False
        self._reaction.clear()
        self._law_types = [law.law for law in self._laws]
        self._v = [0.0] * 6
        self._end_message = f"{self._end_message}; exceeded action ended: {reason}"
        return True

    def _end_move(self, axis: int, condition: int, ok: bool, message: str) -> None:
        self._end = [END_NONE] * 6
        if axis >= 0:
            self._end[axis] = condition
        else:
            for i in self._active:
                self._end[i] = condition
        self._ended_axis = axis
        self._move_active = False
        self._end_ok = ok
        self._end_message = f"move ended: {message}"
        self._outcomes[self._move_id] = ok
        self._outcomes.pop(self._move_id - 64, None)  # keep the last few for blocking callers
        self._v = [0.0] * 6

    def _trip(self, w: list[float] | None) -> None:
        force = (w[0] ** 2 + w[1] ** 2 + w[2] ** 2) ** 0.5 if w else float("nan")
        torque = (w[3] ** 2 + w[4] ** 2 + w[5] ** 2) ** 0.5 if w else float("nan")
        p = self.preprocessor
        if w:
            self._wrench = w  # ~status and the events show the wrench that tripped
        self._latched = True
        self._reaction.clear()  # nothing moves after a safety trip, whatever the exceeded action said
        self._v = [0.0] * 6
        self._latch_message = (
            f"wrench over the global limit (|F| {force:.1f} N of {p.max_force} N, |T| "
            f"{torque:.1f} Nm of {p.max_torque} Nm): holding until reset"
        )
        if self._move_active:
            self._end_move(-1, END_FT_VIOLATION, False, self._latch_message)
