"""Typed settings of contact control, loaded once from the YAML / parameter-server dict and validated.

Every key of the original `contact_control_conf.yaml` is accepted (see the package README); the additions
carry units in their names or in `PARAMETERS` below, which is also the table the README documents. Errors
name the key.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field, fields
from typing import Any

from compliant_common.keys import unknown_key_message

__all__ = ["PARAMETERS", "AxisTuning", "ContactControlSettings", "ParamError", "load_settings"]


class ParamError(ValueError):
    """A configuration value is missing its type or range; `key` names it."""

    def __init__(self, key: str, message: str) -> None:
        super().__init__(f"parameter '{key}': {message}")
        self.key = key


# key: (kind, default, unit, description). kind: str, bool, float, pos (> 0), nonneg (>= 0), sign (+1/-1),
# vec3, vec6, optpos (> 0 or None).
PARAMETERS: dict[str, tuple[str, Any, str, str]] = {
    # topics and frames
    "ft_in_topic": ("str", "wrench", "", "geometry_msgs/WrenchStamped input"),
    "velocity_out_topic": ("str", "/ee_velocity", "", "geometry_msgs/TwistStamped output"),
    "move_group": ("str", "", "", "name of the kinematic chain (informational; no MoveIt here)"),
    "fixed_frame": ("str", "base_link", "", "world-fixed frame; gravity and travel are measured in it"),
    "velocity_command_frame": ("str", "base_link", "", "frame of the published twist"),
    "ft_sensor_frame": ("str", "base_link", "", "frame of the wrench (used when the header frame is empty)"),
    "use_ft_sensor_frame": (
        "bool", False, "", "ignore header.frame_id, take ft_sensor_frame (a recording in a frame tf lacks)",
    ),
    "control_frame": ("str", "base_link", "", "frame whose axes X..RZ the laws act along"),
    "eef_frame": ("str", "tool0", "", "end-effector frame whose travel is measured"),
    # timing
    "control_rate": ("pos", 500.0, "Hz", "stale-check and hold timer rate; nominal cycle for rate limits"),
    "status_rate": ("pos", 50.0, "Hz", "~status publish rate"),
    "wrench_timeout": ("pos", 0.1, "s", "no wrench for longer: output zero (SAFETY_STALE)"),
    "wrench_timeout_periods": (
        "nonneg", 10.0, "", "the stale timeout is at least this many measured sample periods (0: fixed)",
    ),
    "no_data_end_timeout": ("nonneg", 1.0, "s", "stale for longer: the move ends with NO_FT_DATA"),
    "check_stamp_age": ("bool", True, "", "wrenches stamped more than wrench_timeout ago are stale"),
    "future_stamp_tolerance": (
        "nonneg", 0.1, "s", "with check_stamp_age: wrenches stamped further ahead are refused like NaN",
    ),
    "publish_when_idle": ("bool", False, "", "publish zero twists when no move is active"),
    "idle_zero_count": ("nonneg", 10.0, "", "zero twists sent after a move ends, then silence"),
    "publish_synchronously": ("bool", True, "", "send the twist from the wrench callback, no sender thread"),
    # wrench preprocessing
    "lp_filter_enabled": ("bool", True, "", "second-order Butterworth low-pass on the wrench"),
    "lp_filter_delta_t": ("pos", 0.002, "s", "expected sample period: the design until the rate is measured"),
    "lp_filter_cutoff_freq": ("pos", 5.0, "Hz", "cutoff (true at the measured rate: lp_filter_rate_adapt)"),
    "lp_filter_rate_adapt": (
        "bool", True, "", "design the filter for the measured sample period (lp_filter_delta_t until known)",
    ),
    "ft_x_direction": ("sign", 1, "", "legacy sign flip of sensor force X and torque X (prefer tf frames)"),
    "ft_y_direction": ("sign", 1, "", "legacy sign flip of sensor force Y and torque Y"),
    "ft_z_direction": ("sign", 1, "", "legacy sign flip of sensor force Z and torque Z"),
    "travel_x_direction": ("sign", 1, "", "legacy sign flip of the measured travel along X and about X"),
    "travel_y_direction": ("sign", 1, "", "legacy sign flip of the measured travel along Y and about Y"),
    "travel_z_direction": ("sign", 1, "", "legacy sign flip of the measured travel along Z and about Z"),
    "tare_on_startup": ("bool", True, "", "tare with the first valid wrench"),
    "bias": ("vec6", [0.0] * 6, "N, Nm", "sensor offset subtracted before the first tare (sensor frame)"),
    "tool_mass": ("nonneg", 0.0, "kg", "payload below the sensor, gravity-compensated"),
    "tool_com": ("vec3", [0.0, 0.0, 0.0], "m", "payload centre of mass in the sensor frame"),
    "gravity": ("vec3", [0.0, 0.0, -9.81], "m/s^2", "gravity in fixed_frame"),
    "force_deadband": ("nonneg", 0.0, "N", "wrench components below this read as zero (control frame)"),
    "torque_deadband": ("nonneg", 0.0, "Nm", "same for torques"),
    # global limits
    "global_max_force": ("pos", 25.0, "N", "|force| above this: zero output, latched until ~reset"),
    "global_max_torque": ("pos", 25.0, "Nm", "|torque| above this: same"),
    "max_velocity": ("pos", 0.25, "m/s", "clamp of every linear velocity; compliant move speed range"),
    "max_angular_velocity": ("optpos", None, "rad/s", "clamp of angular velocities (default: max_velocity)"),
    # law tuning (the thesis fork's hard-coded numbers, named)
    "follower_deadband_force": ("nonneg", 2.5, "N", "follower ignores smaller forces (decelerates)"),
    "follower_deadband_torque": ("nonneg", 2.5, "Nm", "same for torques"),
    "min_velocity_linear": ("nonneg", 0.005, "m/s", "commands of at most this magnitude become zero"),
    "min_velocity_angular": ("nonneg", 0.005, "rad/s", "same for rotations"),
    "acceleration_linear": ("pos", 2.5, "m/s^2", "limit on speeding up"),
    "acceleration_angular": ("pos", 2.5, "rad/s^2", "same for rotations"),
    "deceleration_linear": ("pos", 2.5, "m/s^2", "limit on slowing down (fork: 0.005 m/s per 2 ms cycle)"),
    "deceleration_angular": ("pos", 2.5, "rad/s^2", "same for rotations"),
    "spring_output_scale": ("pos", 0.2, "", "spring velocity factor (fork: 0.2)"),
    "spring_rounding": ("nonneg", 0.01, "N, m/s", "spring rounds force and velocity to this step (0: off)"),
    "compliant_slowdown_distance": ("nonneg", 0.02, "m", "compliant move slows down this near max travel"),
    "compliant_slowdown_angle": ("nonneg", 0.02, "rad", "same for rotations"),
    "compliant_approach_speed_linear": ("pos", 0.02, "m/s", "slowest compliant move speed when slowing"),
    "compliant_approach_speed_angular": ("pos", 0.02, "rad/s", "same for rotations"),
    "compliant_default_velocity_linear": (
        "pos", 0.01, "m/s",
        "V_desired of a compliant move requested without one, toward its force limit's sign",
    ),
    "compliant_default_velocity_angular": ("pos", 0.05, "rad/s", "same for rotations"),
    # exceeded_action move_away (after a move ended on a force/torque limit)
    "move_away_velocity_linear": ("pos", 0.01, "m/s", "speed of backing off along the contact force"),
    "move_away_velocity_angular": ("pos", 0.05, "rad/s", "same for rotations"),
    "move_away_release_fraction": (
        "pos", 0.5, "",
        "backing off ends once |F| is below this fraction of the axis's force/torque limit (hysteresis)",
    ),
    "move_away_max_distance": ("pos", 0.02, "m", "backing off ends after this distance at the latest"),
    "move_away_max_angle": ("pos", 0.2, "rad", "same for rotations"),
    # force tracking law (ConfigureLaws FORCE_TRACKING)
    "force_tracking_deadband_force": (
        "nonneg", 0.2, "N",
        "force tracking holds still while |F - target| is at most this (no deadband around zero force)",
    ),
    "force_tracking_deadband_torque": ("nonneg", 0.02, "Nm", "same for torques"),
    "force_tracking_contact_fraction": (
        "pos", 0.5, "",
        "force tracking approaches at its approach speed until F reaches this fraction of the target",
    ),
    "diff_max_force": ("nonneg", 0.0, "N", "force change within diff_window that ends a move (0: off)"),
    "diff_max_torque": ("nonneg", 0.0, "Nm", "same for torques"),
    "diff_window": ("pos", 0.1, "s", "time window of the force-jump check"),
    "force_limit_arm_time": (
        "nonneg", 0.5, "s",
        "an axis's force limit is checked once it has reached its law's velocity, or after this (0: at once)",
    ),
}


@dataclass(frozen=True)
class AxisTuning:
    """Law tuning for one kind of axis (linear: N, m, m/s; angular: Nm, rad, rad/s)."""

    deadband: float = 2.5
    min_velocity: float = 0.005
    acceleration: float = 2.5
    deceleration: float = 2.5
    max_velocity: float = 0.25
    slowdown: float = 0.02
    approach_speed: float = 0.02
    diff_max: float = 0.0
    spring_scale: float = 0.2
    spring_rounding: float = 0.01
    default_velocity: float = 0.01
    away_velocity: float = 0.01
    away_max_travel: float = 0.02
    track_deadband: float = 0.2
    contact_fraction: float = 0.5


@dataclass(frozen=True)
class ContactControlSettings:
    """All settings; field names are the parameter keys (see `PARAMETERS` for units)."""

    ft_in_topic: str = "wrench"
    velocity_out_topic: str = "/ee_velocity"
    move_group: str = ""
    fixed_frame: str = "base_link"
    velocity_command_frame: str = "base_link"
    ft_sensor_frame: str = "base_link"
    use_ft_sensor_frame: bool = False
    control_frame: str = "base_link"
    eef_frame: str = "tool0"
    control_rate: float = 500.0
    status_rate: float = 50.0
    wrench_timeout: float = 0.1
    wrench_timeout_periods: float = 10.0
    no_data_end_timeout: float = 1.0
    check_stamp_age: bool = True
    future_stamp_tolerance: float = 0.1
    publish_when_idle: bool = False
    idle_zero_count: float = 10.0
    publish_synchronously: bool = True
    lp_filter_enabled: bool = True
    lp_filter_delta_t: float = 0.002
    lp_filter_cutoff_freq: float = 5.0
    lp_filter_rate_adapt: bool = True
    ft_x_direction: int = 1
    ft_y_direction: int = 1
    ft_z_direction: int = 1
    travel_x_direction: int = 1
    travel_y_direction: int = 1
    travel_z_direction: int = 1
    tare_on_startup: bool = True
    bias: tuple[float, ...] = (0.0,) * 6
    tool_mass: float = 0.0
    tool_com: tuple[float, ...] = (0.0, 0.0, 0.0)
    gravity: tuple[float, ...] = (0.0, 0.0, -9.81)
    force_deadband: float = 0.0
    torque_deadband: float = 0.0
    global_max_force: float = 25.0
    global_max_torque: float = 25.0
    max_velocity: float = 0.25
    max_angular_velocity: float | None = None
    follower_deadband_force: float = 2.5
    follower_deadband_torque: float = 2.5
    min_velocity_linear: float = 0.005
    min_velocity_angular: float = 0.005
    acceleration_linear: float = 2.5
    acceleration_angular: float = 2.5
    deceleration_linear: float = 2.5
    deceleration_angular: float = 2.5
    spring_output_scale: float = 0.2
    spring_rounding: float = 0.01
    compliant_slowdown_distance: float = 0.02
    compliant_slowdown_angle: float = 0.02
    compliant_approach_speed_linear: float = 0.02
    compliant_approach_speed_angular: float = 0.02
    compliant_default_velocity_linear: float = 0.01
    compliant_default_velocity_angular: float = 0.05
    move_away_velocity_linear: float = 0.01
    move_away_velocity_angular: float = 0.05
    move_away_release_fraction: float = 0.5
    move_away_max_distance: float = 0.02
    move_away_max_angle: float = 0.2
    force_tracking_deadband_force: float = 0.2
    force_tracking_deadband_torque: float = 0.02
    force_tracking_contact_fraction: float = 0.5
    diff_max_force: float = 0.0
    diff_max_torque: float = 0.0
    diff_window: float = 0.1
    force_limit_arm_time: float = 0.5
    #: Keys of the input that are not parameters (the node warns about them).
    unknown_keys: tuple[str, ...] = field(default=(), compare=False)

    @property
    def ft_directions(self) -> tuple[int, int, int]:
        return (self.ft_x_direction, self.ft_y_direction, self.ft_z_direction)

    @property
    def travel_directions(self) -> tuple[int, int, int]:
        return (self.travel_x_direction, self.travel_y_direction, self.travel_z_direction)

    @property
    def angular_velocity_limit(self) -> float:
        """max_angular_velocity, or max_velocity when unset (the original clamped all axes with it)."""
        return self.max_velocity if self.max_angular_velocity is None else self.max_angular_velocity

    def tuning(self, angular: bool) -> AxisTuning:
        """The law tuning of linear (False) or angular (True) axes."""
        if angular:
            return AxisTuning(
                self.follower_deadband_torque,
                self.min_velocity_angular,
                self.acceleration_angular,
                self.deceleration_angular,
                self.angular_velocity_limit,
                self.compliant_slowdown_angle,
                self.compliant_approach_speed_angular,
                self.diff_max_torque,
                self.spring_output_scale,
                self.spring_rounding,
                self.compliant_default_velocity_angular,
                self.move_away_velocity_angular,
                self.move_away_max_angle,
                self.force_tracking_deadband_torque,
                self.force_tracking_contact_fraction,
            )
        return AxisTuning(
            self.follower_deadband_force,
            self.min_velocity_linear,
            self.acceleration_linear,
            self.deceleration_linear,
            self.max_velocity,
            self.compliant_slowdown_distance,
            self.compliant_approach_speed_linear,
            self.diff_max_force,
            self.spring_output_scale,
            self.spring_rounding,
            self.compliant_default_velocity_linear,
            self.move_away_velocity_linear,
            self.move_away_max_distance,
            self.force_tracking_deadband_force,
            self.force_tracking_contact_fraction,
        )


def _number(key: str, value: Any) -> float:
    if isinstance(value, bool) or not isinstance(value, int | float):
        raise ParamError(key, f"expected a number, got {value!r}")
    value = float(value)
    if not math.isfinite(value):
        raise ParamError(key, f"must be finite, got {value}")
    return value


def _convert(key: str, kind: str, value: Any) -> Any:
    if kind == "str":
        if not isinstance(value, str):
            raise ParamError(key, f"expected a string, got {value!r}")
        return value
    if kind == "bool":
        if not isinstance(value, bool):
            raise ParamError(key, f"expected true or false, got {value!r}")
        return value
    if kind in ("vec3", "vec6"):
        size = 3 if kind == "vec3" else 6
        if not isinstance(value, list | tuple) or len(value) != size:
            raise ParamError(key, f"expected a list of {size} numbers, got {value!r}")
        return tuple(_number(key, v) for v in value)
    if kind == "optpos" and value is None:
        return None
    number = _number(key, value)
    if kind == "sign":
        if number not in (1.0, -1.0):
            raise ParamError(key, f"must be 1 or -1, got {value!r}")
        return int(number)
    if kind in ("pos", "optpos") and number <= 0.0:
        raise ParamError(key, f"must be > 0, got {value!r}")
    if kind == "nonneg" and number < 0.0:
        raise ParamError(key, f"must be >= 0, got {value!r}")
    return number


def load_settings(params: Mapping[str, Any] | None = None) -> ContactControlSettings:
    """Builds validated settings from a parameter dict.

    Args:
        params: the node's private parameters. Keys may also sit under a `contact_control` sub-dict, as in the
            original YAML; top-level keys win over nested ones. Missing keys take their defaults.

    Returns:
        The settings; `unknown_keys` lists input keys that are not parameters.

    Raises:
        ParamError: a value has the wrong type, is out of range, or breaks a cross-constraint.
    """
    merged: dict[str, Any] = {}
    params = dict(params or {})
    nested = params.pop("contact_control", None)
    if nested is not None:
        if not isinstance(nested, Mapping):
            raise ParamError("contact_control", "expected a dictionary of parameters")
        merged.update(nested)
    merged.update(params)
    values: dict[str, Any] = {}
    for key, (kind, _default, _unit, _doc) in PARAMETERS.items():
        if key in merged:
            values[key] = _convert(key, kind, merged[key])
    unknown = tuple(sorted(k for k in merged if k not in PARAMETERS))
    if unknown:
        raise ParamError(unknown[0], unknown_key_message(unknown[0], PARAMETERS))
    names = {f.name for f in fields(ContactControlSettings)}
    assert names >= set(PARAMETERS), "PARAMETERS and ContactControlSettings disagree"
    settings = ContactControlSettings(**values, unknown_keys=unknown)
    _check_cross_constraints(settings)
    return settings


def _check_cross_constraints(s: ContactControlSettings) -> None:
    if s.lp_filter_enabled and s.lp_filter_cutoff_freq * s.lp_filter_delta_t >= 0.5:
        raise ParamError(
            "lp_filter_cutoff_freq",
            f"cutoff {s.lp_filter_cutoff_freq} Hz is not below the Nyquist frequency "
            f"{0.5 / s.lp_filter_delta_t:.3g} Hz of lp_filter_delta_t {s.lp_filter_delta_t} s",
        )
    for angular in (False, True):
        t = s.tuning(angular)
        suffix = "angular" if angular else "linear"
        if t.min_velocity >= t.max_velocity:
            raise ParamError(f"min_velocity_{suffix}", f"must be below the velocity clamp {t.max_velocity}")
        if t.approach_speed <= t.min_velocity:
            # Slower than min velocity would round to zero and stall the move before its max travel.
            raise ParamError(f"compliant_approach_speed_{suffix}", f"must exceed min_velocity_{suffix}")
        for key, value in (
            (f"compliant_default_velocity_{suffix}", t.default_velocity),
            (f"move_away_velocity_{suffix}", t.away_velocity),
        ):
            # Not above the clamp (it would be cut anyway), above min velocity (it would never move).
            if not t.min_velocity < value <= t.max_velocity:
                raise ParamError(key, f"must exceed min_velocity_{suffix} and not exceed {t.max_velocity}")
    if s.force_tracking_contact_fraction > 1.0:
        raise ParamError("force_tracking_contact_fraction", "must be at most 1 (a fraction of the target)")
    if s.move_away_release_fraction >= 1.0:
        raise ParamError("move_away_release_fraction", "must be below 1 (a fraction of the force limit)")
    if s.no_data_end_timeout and s.no_data_end_timeout < s.wrench_timeout:
        raise ParamError("no_data_end_timeout", "must be 0 or at least wrench_timeout")
