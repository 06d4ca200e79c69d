"""Wrench preprocessing (the original's netft_utils role): sign flips, bias, tool gravity, limits, filter,
frame change and deadband, in that order.

Convention: the result is the external wrench acting on the end effector, as a human pushing it feels it
(push the tool along +Z and F_z > 0), in the control frame's axes, torque about the origin `T_control_sensor`
is relative to (the node passes the end effector's position with the control frame's axes).
The sensor is assumed to read the tool's weight as m * g (g = `gravity` in the fixed frame) plus the external
wrench plus a constant offset. Rotations and transforms are row-major nested sequences or numpy arrays:
`R_world_sensor` maps sensor-frame vectors into the fixed frame, `T_control_sensor` (4x4) maps sensor-frame
points into the control frame. Plain floats throughout: for 6-vectors they beat numpy by a wide margin.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import TypeAlias

from compliant_common.errors import StackError
from compliant_common.typedefs import FloatArray

from contact_control.axes import SAFETY_NAN, SAFETY_OK, SAFETY_OVER_LIMIT
from contact_control.filters import LowPass
from contact_control.params import ContactControlSettings

__all__ = ["Matrix", "PreprocessError", "WrenchPreprocessor", "as_rows", "is_finite6"]


class PreprocessError(StackError):
    """Bad input to a preprocessing request (tare with invalid data, missing orientation)."""


#: A rotation (3x3) or transform (4x4): row-major nested sequences or a numpy array.
Matrix: TypeAlias = Sequence[Sequence[float]] | FloatArray


def as_rows(matrix: Matrix) -> Sequence[Sequence[float]]:
    """Nested rows of a matrix; numpy arrays are converted once (indexing them per element is slow)."""
    if hasattr(matrix, "tolist"):
        rows: list[list[float]] = matrix.tolist()
        return rows
    return matrix


def is_finite6(w: Sequence[float]) -> bool:
    """True when all six numbers are finite (one sum: NaN and inf both poison it)."""
    s = w[0] + w[1] + w[2] + w[3] + w[4] + w[5]
    return s - s == 0.0


class WrenchPreprocessor:
    """Turns raw sensor wrenches into control-frame wrenches; holds bias and filter state."""

    def __init__(self, settings: ContactControlSettings) -> None:
        self._signs = settings.ft_directions
        self._flip = self._signs != (1, 1, 1)
        self._bias = [float(b) for b in settings.bias]
        # The pose-dependent offset a bias map predicts (set_pose_bias); `_offset` = bias + it, per cycle.
        self._pose_bias = [0.0] * 6
        self._offset = list(self._bias)
        self._tool = (settings.tool_mass, tuple(settings.tool_com))
        self._gravity = tuple(settings.gravity)
        self.set_load_error(0.0, (0.0, 0.0, 0.0))
        self.set_limits(settings.global_max_force, settings.global_max_torque)
        self.set_deadband(settings.force_deadband, settings.torque_deadband)
        self._filter: LowPass | None = None
        # The last sample unfiltered, in the control frame (what `process` gives before the low-pass, no
        # deadband), kept while `keep_fast` is set: force tracking's pressing guard reads it.
        self.keep_fast = False
        self.fast = [0.0] * 6
        self._cutoff = settings.lp_filter_cutoff_freq
        self.design_period = settings.lp_filter_delta_t  # [s] the filter's current design sample period
        if settings.lp_filter_enabled:
            self.set_filter(True, settings.lp_filter_delta_t, settings.lp_filter_cutoff_freq)

    # --- configuration (netft_utils-style setters) ---
    @property
    def bias(self) -> tuple[float, ...]:
        """Current offset subtracted from the (sign-flipped) sensor wrench, net of tool gravity at tare."""
        return tuple(self._bias)

    def set_bias(self, bias: Sequence[float], at_rest: bool = False) -> None:
        """Sets the offset directly (sensor frame, after sign flips). `at_rest`: it is the mean of the current
        readings, so the filter restarts from zero (not from the next sample, which holds a whole sample's
        noise)."""
        if len(bias) != 6 or not is_finite6(bias):
            raise PreprocessError(f"bias must be 6 finite numbers, got {bias!r}")
        self._bias = [float(b) for b in bias]
        self._offset = [b + p for b, p in zip(self._bias, self._pose_bias, strict=True)]
        if self._filter:
            self._filter.reset([0.0] * 6 if at_rest else None)

    def set_load_error(self, mass: float, moment: Sequence[float]) -> None:
        """A load the sensor carries beyond the configured tool: mass [kg] (may be negative) and first
        moment (mass times centre of mass) [kg m] in the sensor frame (a bias map's load part)."""
        tool_mass, com = self._tool
        self._mass = tool_mass + mass
        self._moment = tuple(tool_mass * c + h for c, h in zip(com, moment, strict=True))
        self._mg = [self._mass * g for g in self._gravity]
        self._weighs = bool(self._mass) or any(self._moment)

    @property
    def weighs(self) -> bool:
        """Whether a load is compensated (then every wrench needs the sensor's orientation)."""
        return self._weighs

    @property
    def pose_bias(self) -> tuple[float, ...]:
        """The pose-dependent offset subtracted now (a bias map's residual at the current joints)."""
        return tuple(self._pose_bias)

    def set_pose_bias(self, values: Sequence[float]) -> None:
        """The pose-dependent offset at the current joint positions [N, Nm], sensor frame after sign flips:
        subtracted from every wrench beside the bias, and left out of what `tare` stores."""
        p, o, b = self._pose_bias, self._offset, self._bias
        for i in range(6):
            p[i] = values[i]
            o[i] = b[i] + p[i]

    def set_limits(self, max_force: float, max_torque: float) -> None:
        """Global limits on |force| [N] and |torque| [Nm] of the compensated sensor wrench."""
        if not (max_force > 0.0 and max_torque > 0.0 and math.isfinite(max_force + max_torque)):
            raise PreprocessError(f"limits must be finite and > 0, got {max_force}, {max_torque}")
        self.max_force, self.max_torque = max_force, max_torque
        self._fmax2, self._tmax2 = max_force * max_force, max_torque * max_torque

    def set_deadband(self, force: float, torque: float) -> None:
        """Components below these magnitudes [N], [Nm] read as zero (control frame)."""
        if not (force >= 0.0 and torque >= 0.0 and math.isfinite(force + torque)):
            raise PreprocessError(f"deadbands must be finite and >= 0, got {force}, {torque}")
        self._db_force, self._db_torque = force, torque
        self._deadband = force > 0.0 or torque > 0.0

    def set_filter(self, enabled: bool, delta_t: float = 0.2, cutoff_freq: float = 0.6) -> None:
        """Switches the low-pass filter (see `filters`); a new filter starts from the next sample."""
        if not enabled:
            self._filter = None
            return
        try:
            self._filter = LowPass(delta_t, cutoff_freq, 6)
        except ValueError as err:
            raise PreprocessError(str(err)) from err
        self._cutoff, self.design_period = cutoff_freq, delta_t

    @property
    def cutoff(self) -> float:
        """The low-pass filter's cutoff at its current design [Hz]."""
        return min(self._cutoff, 0.45 / self.design_period)

    def set_cutoff(self, cutoff_freq: float) -> float | None:
        """A new cutoff [Hz] at the filter's current design period, continuing from its last output (no step).
        Returns the cutoff used (capped as in `redesign_filter`), None without a filter."""
        self._cutoff = cutoff_freq
        return self.redesign_filter(self.design_period)

    def redesign_filter(self, period: float) -> float | None:
        """Designs the filter anew for samples `period` [s] apart, keeping its cutoff in Hz (below 0.45 of the
        sample rate: closer to Nyquist the bilinear design degenerates); continues from its last output, so
        the change makes no step. Returns the cutoff used, None without a filter."""
        old = self._filter
        if old is None:
            return None
        cutoff = min(self._cutoff, 0.45 / period)
        new = LowPass(period, cutoff, 6)
        if old.last is not None:
            new.reset(old.last)
        self._filter, self.design_period = new, period
        return cutoff

    # --- tool gravity and tare ---
    def gravity_wrench(self, R_world_sensor: Matrix | None) -> list[float]:
        """The tool's weight as the sensor reads it at this orientation (sensor frame, about its origin)."""
        if not self._weighs:
            return [0.0] * 6
        if R_world_sensor is None:
            raise PreprocessError("a tool mass is set, so the sensor orientation R_world_sensor is needed")
        r = as_rows(R_world_sensor)
        gx, gy, gz = self._gravity
        # u = R^T g: gravity in the sensor frame; the load's wrench is (m u, h x u).
        ux = r[0][0] * gx + r[1][0] * gy + r[2][0] * gz
        uy = r[0][1] * gx + r[1][1] * gy + r[2][1] * gz
        uz = r[0][2] * gx + r[1][2] * gy + r[2][2] * gz
        m = self._mass
        hx, hy, hz = self._moment
        return [m * ux, m * uy, m * uz, hy * uz - hz * uy, hz * ux - hx * uz, hx * uy - hy * ux]

    def oriented(self, raw: Sequence[float]) -> list[float]:
        """The raw wrench with the configured sign flips (what `gravity_wrench` + bias model), a new list."""
        return self._flipped(raw)

    def _flipped(self, raw: Sequence[float]) -> list[float]:
        w = [float(v) for v in raw]
        if self._flip:
            for i in range(3):
                w[i] *= self._signs[i]
                w[i + 3] *= self._signs[i]
        return w

    def tare(self, raw: Sequence[float], R_world_sensor: Matrix | None = None) -> tuple[float, ...]:
        """Makes the current reading the zero: stores the bias net of the tool's expected weight here.

        After tare the compensated wrench is zero at this orientation and stays near zero when the sensor
        is reoriented without contact, because only the constant offset was absorbed into the bias.

        Raises:
            PreprocessError: the reading is not finite or the orientation is missing while tool_mass > 0.
        """
        self.set_bias(self.bias_estimate(raw, R_world_sensor))
        return tuple(self._bias)

    def bias_estimate(self, raw: Sequence[float], R_world_sensor: Matrix | None = None) -> list[float]:
        """The bias that would make this reading zero (what `tare` stores), changing nothing.

        Raises:
            PreprocessError: As `tare`.
        """
        if len(raw) != 6 or not is_finite6(raw):
            raise PreprocessError(f"cannot tare with an invalid wrench {raw!r}")
        expected = self.gravity_wrench(R_world_sensor)
        w = self._flipped(raw)
        p = self._pose_bias
        return [w[i] - expected[i] - p[i] for i in range(6)]

    def contact_force(
        self, raw: Sequence[float], R_world_sensor: Matrix | None = None
    ) -> tuple[float, float, float] | None:
        """The force of a raw wrench with sign flips, bias and the tool's weight taken out, sensor frame [N],
        unfiltered and unchecked (no state changes); None for a NaN/inf wrench or, with a tool mass, a
        missing orientation."""
        fx, fy, fz, tx, ty, tz = raw
        s = fx + fy + fz + tx + ty + tz
        if s - s != 0.0:
            return None
        if self._flip:
            sx, sy, sz = self._signs
            fx, fy, fz = fx * sx, fy * sy, fz * sz
        b = self._offset
        fx, fy, fz = float(fx) - b[0], float(fy) - b[1], float(fz) - b[2]
        if self._weighs:
            if R_world_sensor is None:
                return None
            r = as_rows(R_world_sensor)
            gx, gy, gz = self._mg  # R^T (m g): the weight in the sensor frame
            fx -= r[0][0] * gx + r[1][0] * gy + r[2][0] * gz
            fy -= r[0][1] * gx + r[1][1] * gy + r[2][1] * gz
            fz -= r[0][2] * gx + r[1][2] * gy + r[2][2] * gz
        return fx, fy, fz

    # --- the cycle ---
    def process(
        self,
        raw: Sequence[float],
        T_control_sensor: Matrix | None = None,
        R_world_sensor: Matrix | None = None,
    ) -> tuple[int, list[float] | None]:
        """One sample through the chain.

        Args:
            raw: sensor wrench (fx, fy, fz, tx, ty, tz) [N, Nm] in the sensor frame.
            T_control_sensor: 4x4 sensor pose in the control frame; None when they coincide.
            R_world_sensor: 3x3 sensor orientation in the fixed frame; needed when tool_mass > 0.

        Returns:
            (SAFETY_OK, control-frame wrench), (SAFETY_NAN, None) for NaN/inf input, or
            (SAFETY_OVER_LIMIT, compensated sensor-frame wrench) when a global limit is exceeded.
            Neither failure touches the filter state.
        """
        fx, fy, fz, tx, ty, tz = raw
        s = fx + fy + fz + tx + ty + tz
        if s - s != 0.0:
            return SAFETY_NAN, None
        if self._flip:
            sx, sy, sz = self._signs
            fx, fy, fz, tx, ty, tz = fx * sx, fy * sy, fz * sz, tx * sx, ty * sy, tz * sz
        b = self._offset
        fx, fy, fz, tx, ty, tz = fx - b[0], fy - b[1], fz - b[2], tx - b[3], ty - b[4], tz - b[5]
        if self._weighs:
            g = self.gravity_wrench(R_world_sensor)
            fx, fy, fz, tx, ty, tz = fx - g[0], fy - g[1], fz - g[2], tx - g[3], ty - g[4], tz - g[5]
        if fx * fx + fy * fy + fz * fz > self._fmax2 or tx * tx + ty * ty + tz * tz > self._tmax2:
            return SAFETY_OVER_LIMIT, [fx, fy, fz, tx, ty, tz]
        m = None if T_control_sensor is None else as_rows(T_control_sensor)
        if self.keep_fast:
            self.fast[:] = (fx, fy, fz, tx, ty, tz) if m is None else _to_control(m, fx, fy, fz, tx, ty, tz)
        if self._filter is not None:
            fx, fy, fz, tx, ty, tz = self._filter.step((fx, fy, fz, tx, ty, tz))
        if m is not None:
            fx, fy, fz, tx, ty, tz = _to_control(m, fx, fy, fz, tx, ty, tz)
        out = [fx, fy, fz, tx, ty, tz]
        if self._deadband:
            dbf, dbt = self._db_force, self._db_torque
            for i in range(3):
                if -dbf < out[i] < dbf:
                    out[i] = 0.0
                if -dbt < out[i + 3] < dbt:
                    out[i + 3] = 0.0
        return SAFETY_OK, out


def _to_control(
    m: Sequence[Sequence[float]], fx: float, fy: float, fz: float, tx: float, ty: float, tz: float
) -> tuple[float, float, float, float, float, float]:
    """A sensor-frame wrench in the control frame (`m`: T_control_sensor's rows), torque about its origin."""
    r0, r1, r2 = m[0], m[1], m[2]
    px, py, pz = r0[3], r1[3], r2[3]
    cfx = r0[0] * fx + r0[1] * fy + r0[2] * fz
    cfy = r1[0] * fx + r1[1] * fy + r1[2] * fz
    cfz = r2[0] * fx + r2[1] * fy + r2[2] * fz
    # Torque about the reference origin: rotated sensor torque plus lever arm p x F.
    return (
        cfx, cfy, cfz,
        r0[0] * tx + r0[1] * ty + r0[2] * tz + py * cfz - pz * cfy,
        r1[0] * tx + r1[1] * ty + r1[2] * tz + pz * cfx - px * cfz,
        r2[0] * tx + r2[1] * ty + r2[2] * tz + px * cfy - py * cfx,
    )
