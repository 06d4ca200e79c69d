"""The wrench on its way in, before any law sees it: the stamp's age, the sensor's measured rate (the filter
and the stale timeout follow it), zeroing over a steady window with the noise floor it measures, tare, and
the zero's drift watched at rest (no ROS here; the package README's "Zeroing" and "Noise floor")."""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence

from contact_control.axes import AXES, SAFETY_NAN, SAFETY_STALE, SAFETY_ZEROING
from contact_control.drift import ZeroDrift
from contact_control.laws import AxisLaw
from contact_control.noise_floor import NoiseFloor
from contact_control.params import ContactControlSettings
from contact_control.preprocess import Matrix, PreprocessError, WrenchPreprocessor, as_rows, is_finite6
from contact_control.rate import SamplePeriod
from contact_control.request import SET_CONTROL_FORCE_FAILED, RequestError
from contact_control.zeroing import SteadyZero

__all__ = ["WrenchIntake"]

_DRIFT_PERIOD = 0.02  # [s] between the drift watch's samples at rest


class WrenchIntake:
    """Stamps, rate, zero and noise floor of the sensor's wrenches; the preprocessor does the rest.

    Args:
        settings: checked settings.
        notes: where to append what the node should log once.
        on_floor: called when a noise floor has been measured.
    """

    def __init__(self, settings: ContactControlSettings, notes: list[str],
                 on_floor: Callable[[], None]) -> None:
        s = self.settings = settings
        self.preprocessor = WrenchPreprocessor(s)
        self.notes = notes
        self._on_floor = on_floor
        #: The stale timeout in use [s]: wrench_timeout, or wrench_timeout_periods periods if longer.
        self.wrench_timeout = s.wrench_timeout
        self.rate = SamplePeriod()
        self._adapt_filter = s.lp_filter_rate_adapt and s.lp_filter_enabled
        self._check_age, self._future = s.check_stamp_age, s.future_stamp_tolerance
        #: When the newest valid wrench arrived [s] (None: none yet, or since a restart of the timing).
        self.last_wrench_time: float | None = None
        self.last_raw: Sequence[float] | None = None  # the newest wrench as received (sensor frame)
        self._last_R: Matrix | None = None
        self.tare_pending = s.tare_on_startup
        self._zeroing = self._new_zeroing() if s.tare_on_startup else None
        #: The sensor's noise at rest, measured while zeroing (None before, or if not zeroed).
        self.noise_floor: NoiseFloor | None = None
        #: How far the offset moves over the workspace beyond the noise (force [N], torque [Nm]): a bias
        #: map's held-out residual, else the declared pose_offset_force / _torque.
        self.pose_residual = (s.pose_offset_force, s.pose_offset_torque)
        self.drift = (ZeroDrift(s.drift_window, s.tare_max_force_spread, s.tare_max_torque_spread,
                                s.tare_spread_sigmas)
                      if s.drift_window > 0.0 else None)
        self._drift_next = 0.0  # when the drift watch takes its next sample [s]

    @property
    def zeroing(self) -> bool:
        """Zeroing has not finished yet (the laws hold still until it has)."""
        return self.tare_pending

    @property
    def sample_period(self) -> float | None:
        """The sensor's measured sample period [s] (None until measured)."""
        return self.rate.period

    @property
    def fresh_until(self) -> float:
        """Time [s] until which the newest wrench counts as fresh (-inf before the first one)."""
        last = self.last_wrench_time
        return -math.inf if last is None else last + self.wrench_timeout

    @property
    def zero_drift(self) -> tuple[float, ...] | None:
        """How far the zero has moved since the bias was set, measured at rest [N, Nm], sensor frame (None:
        not yet measured)."""
        return None if self.drift is None else self.drift.drift

    def receive(self, wrench: Sequence[float], t: float, stamp: float | None,
                R_world_sensor: Matrix | None) -> tuple[int, str] | None:
        """A wrench received at `t` (stamped `stamp`, or None): None when it goes on to the laws, else the
        safety code and why the output holds (stale, stamped ahead, zeroing)."""
        if self.rate.add(t if stamp is None else stamp):
            self._on_sample_period(self.rate.period)  # type: ignore[arg-type]
        if stamp is not None and self._check_age:
            age, timeout = t - stamp, self.wrench_timeout
            if age > timeout:
                return SAFETY_STALE, f"wrench stamp is {age:.3f} s old (wrench_timeout {timeout} s)"
            future = self._future
            if stamp - t > future:  # another clock, or data from before a backward clock jump
                self.last_wrench_time = t
                ahead = f"wrench stamped {stamp - t:.3f} s ahead (future_stamp_tolerance {future} s)"
                return SAFETY_NAN, f"{ahead}: holding until data stamped by this node's clock"
        self.last_wrench_time = t
        self.last_raw, self._last_R = wrench, R_world_sensor
        if self.tare_pending and is_finite6(wrench):
            return self._zero(wrench, R_world_sensor, t)
        return None

    def retune(self, s: ContactControlSettings) -> list[str]:
        """New checked settings (live tuning): the global limits and the filter's cutoff apply at once, the
        filter continuing from its last output. Returns what changed, in words."""
        old, self.settings = self.settings, s
        changed = []
        if (s.global_max_force, s.global_max_torque) != (old.global_max_force, old.global_max_torque):
            self.preprocessor.set_limits(s.global_max_force, s.global_max_torque)
            changed.append(f"global limits {s.global_max_force:g} N, {s.global_max_torque:g} Nm")
        if s.lp_filter_cutoff_freq != old.lp_filter_cutoff_freq:
            used = self.preprocessor.set_cutoff(s.lp_filter_cutoff_freq)
            changed.append("no filter" if used is None else f"filter cutoff {used:.3g} Hz")
        return changed

    def loop_timing(self) -> tuple[float, float | None]:
        """The sample period the loop gains are bounded for (`lp_filter_delta_t` until measured) and the
        filter's cutoff [Hz] (None: no filter)."""
        cutoff = self.preprocessor.cutoff if self.settings.lp_filter_enabled else None
        return self.rate.period or self.settings.lp_filter_delta_t, cutoff

    def restart_timing(self) -> None:
        """After a clock jump: no wrench counts as received, the rate is measured again."""
        self.last_wrench_time = None
        self.rate.reset()

    def _on_sample_period(self, period: float) -> None:
        """Keeps the filter's cutoff (in Hz) and the stale timeout true to the sensor's measured rate."""
        s = self.settings
        if s.wrench_timeout_periods > 0.0:
            self.wrench_timeout = max(s.wrench_timeout, s.wrench_timeout_periods * period)
        pre = self.preprocessor
        if self._adapt_filter and abs(period - pre.design_period) > 0.1 * pre.design_period:
            cutoff = pre.redesign_filter(period)
            rate = 1.0 / period
            note = f"low-pass filter designed for the measured {rate:.4g} Hz wrench (cutoff {cutoff:.3g}"
            configured = s.lp_filter_delta_t
            if abs(period - configured) > 0.2 * configured:
                note += f" Hz; lp_filter_delta_t says {configured} s, {1.0 / configured:.4g}"
            self.notes.append(f"{note} Hz); stale after {self.wrench_timeout:.3g} s")

    # --- the zero ---
    def _zero(self, wrench: Sequence[float], R_world_sensor: Matrix | None,
              t: float) -> tuple[int, str] | None:
        """Start-up (or requested) zeroing: on this wrench, or over a steady window (holding meanwhile)."""
        zeroing = self._zeroing
        if zeroing is None:
            self.preprocessor.tare(wrench, R_world_sensor)
        else:
            bias = zeroing.add(self.preprocessor.bias_estimate(wrench, R_world_sensor), t)
            if bias is None:
                return SAFETY_ZEROING, zeroing.note
            self.preprocessor.set_bias(bias, at_rest=True)
            self.notes.append(
                f"sensor zeroed over {zeroing.duration:.3g} s: bias "
                f"[{', '.join(f'{b:.3g}' for b in bias)}] (N, Nm, sensor frame, tool weight out)"
            )
            self._measure_floor(zeroing)
        self.tare_pending = False
        if self.drift is not None:  # a new window from the new zero; a drift measured before is 0 now
            if self.drift.drift is None:
                self.drift.restart()
            else:
                self.drift.rezeroed()
        return None

    def tare(self, wrench: Sequence[float] | None = None, R_world_sensor: Matrix | None = None
             ) -> tuple[float, ...]:
        """Zeroes the sensor at the newest (or given) reading; see `WrenchPreprocessor.tare`.

        Raises:
            PreprocessError: no valid wrench to tare with; the bias is unchanged.
        """
        if wrench is None:
            if self.last_raw is None:
                raise PreprocessError("no wrench received yet")
            wrench, R_world_sensor = self.last_raw, self._last_R
        bias = self.preprocessor.tare(wrench, R_world_sensor)
        self.tare_pending = False
        if self.drift is not None:  # the zero is here now
            self.drift.rezeroed()
        return bias

    def start_zeroing(self) -> None:
        """Zeroing again over a steady window from the next wrench (`tare_window` 0: on that wrench)."""
        self._zeroing = self._new_zeroing()
        self.tare_pending = True

    def cancel_zeroing(self) -> str:
        """Gives up a zeroing that has not finished: the bias stays. Returns why it was waiting."""
        note = self._zeroing.note if self._zeroing is not None else "no valid wrench"
        self.tare_pending = False
        return note

    def _new_zeroing(self) -> SteadyZero | None:
        s = self.settings
        if s.tare_window <= 0.0:
            return None
        return SteadyZero(s.tare_window, s.tare_max_force_spread, s.tare_max_torque_spread,
                          int(s.tare_min_samples), s.tare_spread_sigmas)

    # --- the noise floor ---
    def _measure_floor(self, zeroing: SteadyZero) -> None:
        """The noise floor of the zeroing window; the deadbands grow to `noise_deadband_sigmas` of it."""
        s = self.settings
        n = zeroing.count
        period = self.rate.period
        rate = 1.0 / period if period else (n - 1) / zeroing.duration if zeroing.duration > 0.0 else 0.0
        if n < 2 or rate <= 0.0:
            return
        cutoff = self.preprocessor.cutoff if s.lp_filter_enabled else None
        floor = NoiseFloor.measure(zeroing.std(), rate, n, cutoff, zeroing.lag1())
        self.noise_floor = floor
        self._on_floor()
        if self.drift is not None:  # steady at rest now means within this noise (from the next window)
            self.drift.noise = floor.std
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

    def resolvable(self) -> tuple[float, float]:
        """The smallest force [N] and torque [Nm] limits a request may set (0, 0: unknown or unchecked)."""
        sigmas = self.settings.noise_limit_sigmas
        if self.noise_floor is None or sigmas <= 0.0:
            return 0.0, 0.0
        force, torque = self.noise_floor.resolvable(sigmas)
        pose_force, pose_torque = self.pose_residual
        return math.hypot(force, sigmas * pose_force), math.hypot(torque, sigmas * pose_torque)

    # --- the zero's drift ---
    def watch_drift(self, wrench: Sequence[float], R_world_sensor: Matrix | None, t: float) -> None:
        """A wrench at rest for the drift watch (one sample per _DRIFT_PERIOD); re-tares when the policy
        (auto_tare_drift) says so."""
        if self.drift is None or t < self._drift_next:
            return
        self._drift_next = t + _DRIFT_PERIOD
        try:
            estimate = self.preprocessor.bias_estimate(wrench, R_world_sensor)
        except PreprocessError:  # no orientation for the tool's weight: no estimate
            return
        bias = self.preprocessor.bias
        drift = self.drift.add(estimate, bias, t)
        limit = self.settings.auto_tare_drift
        if drift is None or limit <= 0.0 or self.drift.force <= limit:
            return
        moved = self.drift.force
        self.preprocessor.set_bias([b + d for b, d in zip(bias, drift, strict=True)], at_rest=True)
        self.drift.rezeroed()
        self.notes.append(f"re-tared at rest: the zero had moved by {moved:.3g} N (auto_tare_drift "
                          f"{limit:g} N)")

    # --- what the sensor resolves ---
    def check_resolvable(self, laws: Sequence[AxisLaw]) -> None:
        """Refuses limits the sensor cannot tell from its noise.

        Raises:
            RequestError: SET_CONTROL_FORCE_FAILED naming the axis, the limit and the noise floor.
        """
        floor = self.noise_floor
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
