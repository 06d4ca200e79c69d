"""Typed settings of contact control, loaded once from the YAML / parameter-server dict and validated.

Every key of the original `contact_control_conf.yaml` is accepted (see the package README). Each parameter
is declared once, as a field of `ContactControlSettings` (name, type, default, unit, range, doc); `PARAMETERS`
is that declaration as a schema, which validates the input and generates the README's table. Errors name
the key.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

from compliant_common.errors import StackError
from compliant_common.schema import SchemaError, param, schema_of
from compliant_common.typedefs import ParamMap

from contact_control.axes import AXES

__all__ = ["PARAMETERS", "TUNABLE", "AxisTuning", "ContactControlSettings", "ParamError", "load_settings"]


class ParamError(StackError):
    """A configuration value is missing its type or range; `key` names it."""

    def __init__(self, key: str, message: str) -> None:
        super().__init__(f"parameter '{key}': {message}")
        self.key = key


def _pos(default: float, unit: str, doc: str) -> float:
    return param(default, unit=unit, gt=0.0, doc=doc)


def _nonneg(default: float, unit: str, doc: str) -> float:
    return param(default, unit=unit, ge=0.0, doc=doc)


def _sign(doc: str) -> int:
    return param(1, type="sign", doc=doc)


@dataclass(frozen=True)
class ContactControlSettings:
    """All settings; field names are the parameter keys, each declared once here (unit, range, doc)."""

    # topics and frames
    ft_in_topic: str = param("wrench", doc="geometry_msgs/WrenchStamped input (original name)")
    velocity_out_topic: str = param("/ee_velocity", doc="geometry_msgs/TwistStamped output (original name)")
    robot_stop_topic: str = param(
        "jog_arm_server/robot_stop", doc="std_msgs/String, latched: why the robot stopped by itself ('' "
        "while it runs; jog_arm README, *Robot stops*): a running move ends with it and requests are refused")
    move_group: str = param("", doc="original: MoveIt group; informational here, the EEF is `eef_frame`")
    fixed_frame: str = param(
        "base_link", doc="world-fixed frame with z up; gravity and travel are measured in it"
    )
    velocity_command_frame: str = param("base_link", doc="frame of the published twist")
    ft_sensor_frame: str = param(
        "base_link", doc="frame of the wrench when its `header.frame_id` is empty (or `use_ft_sensor_frame`)"
    )
    use_ft_sensor_frame: bool = param(
        False,
        doc="ignore the wrench's `header.frame_id` and take `ft_sensor_frame` (a recording whose frame tf "
        "lacks)",
    )
    control_frame: str = param("base_link", doc="frame whose axes X..RZ the laws act along")
    eef_frame: str = param("tool0", doc="end effector whose travel is measured (new)")
    # timing
    control_rate: float = _pos(
        500.0, "Hz", "rate of the zeros while wrenches are stale; nominal cycle of the rate limits"
    )
    status_rate: float = _pos(50.0, "Hz", "`~status` publish rate")
    wrench_timeout: float = _pos(
        0.1, "s", "no wrench for longer: output zero (SAFETY_STALE); the floor when the rate is measured"
    )
    wrench_timeout_periods: float = _nonneg(
        10.0, "", "stale after this many measured sample periods if that is longer (0: fixed timeout)"
    )
    no_data_end_timeout: float = param(
        1.0, unit="s", ge=0.0, shown_range="0 or >= `wrench_timeout`",
        doc="stale this long ends the move with NO_FT_DATA (0: at once)",
    )
    check_stamp_age: bool = param(
        True,
        doc="wrenches stamped more than `wrench_timeout` ago are stale (false for sensors with another "
        "clock)",
    )
    future_stamp_tolerance: float = _nonneg(
        0.1, "s", "with `check_stamp_age`: a stamp further ahead of the node's clock is refused like NaN"
    )
    publish_when_idle: bool = param(False, doc="publish zero twists when no move is active")
    idle_zero_count: float = _nonneg(10.0, "", "zero twists sent after a move ends, then silence")
    publish_synchronously: bool = param(
        True, doc="send the twist from the wrench callback, no sender thread (see *Node*; new)"
    )
    # wrench preprocessing
    lp_filter_enabled: bool = param(True, doc="second-order Butterworth low-pass on the wrench")
    lp_filter_delta_t: float = _pos(
        0.002, "s", "expected sample period: the filter's design until the rate is measured (fork: 0.2 s)"
    )
    lp_filter_cutoff_freq: float = param(
        5.0, unit="Hz", gt=0.0, shown_range="> 0, < 0.5 / `lp_filter_delta_t`",
        doc="cutoff, true at the measured rate with `lp_filter_rate_adapt` (fork: 0.6 Hz)",
    )
    lp_filter_rate_adapt: bool = param(
        True, doc="design the filter for the measured sample period (`lp_filter_delta_t` until known)"
    )
    ft_x_direction: int = _sign(
        "legacy sign flip of sensor force X and torque X (the fork used -1 on one arm; prefer correct frames)"
    )
    ft_y_direction: int = _sign("legacy sign flip of sensor force Y and torque Y")
    ft_z_direction: int = _sign("legacy sign flip of sensor force Z and torque Z")
    travel_x_direction: int = _sign("legacy sign flip of the measured travel along X and about X")
    travel_y_direction: int = _sign("legacy sign flip of the measured travel along Y and about Y")
    travel_z_direction: int = _sign(
        "legacy sign flip of the measured travel along Z and about Z (the original used -1 for one arm)"
    )
    tare_on_startup: bool = param(
        True, doc="zero the sensor at start-up: the mean wrench over `tare_window` (laws hold still)"
    )
    tare_window: float = _nonneg(
        0.2, "s", "start-up zeroing averages this long of steady wrenches; 0: the first valid wrench alone"
    )
    tare_max_force_spread: float = _pos(
        4.0, "N", "a force component moving more than this (peak to peak) within the window restarts it "
        "(a touch or a jolt); above the sensor's noise"
    )
    tare_max_torque_spread: float = _pos(0.4, "Nm", "same for torques")
    tare_spread_sigmas: float = _nonneg(
        8.0, "noise stds", "the spread limits grow to this many noise stds for a noisy sensor (the std of "
        "the window's first `tare_min_samples`, median-based; a current estimate has 3.6 N); 0: fixed limits"
    )
    bias: tuple[float, ...] = param(
        (0.0,) * 6, type="floats", length=6, unit="N, Nm",
        doc="known sensor offset (sensor frame) subtracted until the first tare",
    )
    bias_map: str = param(
        "", doc="path of a bias map file (`calibrate_bias`, README *Bias map*): the sensor's offset as a "
        "function of the joint positions, subtracted every cycle; empty: none"
    )
    bias_map_joint_states: str = param(
        "joint_states", doc="sensor_msgs/JointState input of contact_control_node when `bias_map` is set "
        "(control_stack_node uses jog_arm's)"
    )
    pose_offset_force: float = _nonneg(
        0.0, "N", "how far the sensor's offset moves over the workspace without a `bias_map` (a driver's "
        "documented pose-dependent error): force limits below `noise_limit_sigmas` of it and the noise are "
        "refused; with a map its held-out residual counts instead; 0: unknown"
    )
    pose_offset_torque: float = _nonneg(0.0, "Nm", "same for torques")
    tare_min_samples: float = _nonneg(
        25.0, "", "start-up zeroing also waits for this many samples (0.83 s of a 30 Hz sensor): the noise "
        "floor (std per axis) is measured over the same window"
    )
    noise_deadband_sigmas: float = _nonneg(
        4.0, "filtered noise stds", "`force_deadband` / `torque_deadband` are at least this many filtered "
        "noise stds of the noise floor measured at zeroing (0: only the configured deadbands)"
    )
    noise_limit_sigmas: float = _nonneg(
        5.0, "filtered noise stds", "a request's force/torque limit below this many filtered noise stds is "
        "refused (the sensor cannot tell it from its noise); 0: not checked"
    )
    force_limit_samples: float = param(
        2.0, ge=1.0, doc="a force/torque limit ends a move, and a global limit latches, once exceeded on "
        "this many wrenches in a row (one spike does not; 1: the first, as the fork)"
    )
    command_latency: float = _nonneg(
        0.01, "s", "the command path's latency: the jogger's period, the driver, the arm's servo (the laws' "
        "gains are bounded with it; README, Loop gain)"
    )
    loop_gain_delay: float = _nonneg(
        0.5, "", "a spring's gain (scale x k) and force tracking's (contact_stiffness / b) times the loop's "
        "delay (sensor period + command_latency, + the filter's delay on force) at most this; a request over "
        "it is lowered and the answer says so (0: no bound)"
    )
    contact_stiffness: float = _nonneg(
        0.0, "N/m", "the surfaces force tracking presses on, to bound its gain (0: unknown, not bounded)"
    )
    oscillation_reversals: float = _nonneg(
        6.0, "", "an axis whose commanded velocity reverses this often within `oscillation_window` "
        "oscillates: its gain is halved once, then the move stops (OSCILLATION); 0: no watchdog"
    )
    oscillation_window: float = _pos(2.0, "s", "the watchdog's window")
    drift_window: float = _nonneg(
        1.0, "s", "at rest (no law, no exceeded action) the zero's drift is measured over windows this long "
        "of steady wrenches (the tare spreads), sampled at 50 Hz; 0: not watched"
    )
    auto_tare_drift: float = _nonneg(
        0.0, "N", "re-tare at rest once the zero has drifted by more than this (0: never; `~tare` on request)"
    )
    tool_mass: float = _nonneg(
        0.0, "kg", "payload below the sensor, gravity-compensated (the robot package's description.args "
        "`--tool-mass`)"
    )
    tool_com: tuple[float, ...] = param(
        (0.0, 0.0, 0.0), type="floats", length=3, unit="m",
        doc="payload centre of mass in the sensor frame (description.args `--tool-com`)",
    )
    gravity: tuple[float, ...] = param(
        (0.0, 0.0, -9.81), type="floats", length=3, unit="m/s^2", doc="gravity in `fixed_frame`"
    )
    force_deadband: float = _nonneg(0.0, "N", "force components below this read as zero (control frame)")
    torque_deadband: float = _nonneg(0.0, "Nm", "same for torques")
    # global limits
    global_max_force: float = _pos(25.0, "N", "|force| above this: zero output, latched until `~reset`")
    global_max_torque: float = _pos(25.0, "Nm", "|torque| above this: same")
    max_velocity: float = _pos(0.25, "m/s", "clamp of every linear velocity; compliant move speed range")
    max_angular_velocity: float | None = param(
        None, type="float", optional=True, gt=0.0, unit="rad/s", shown_default="= `max_velocity`",
        doc="clamp of angular velocities (unset: `max_velocity`, the original's one clamp for all axes)",
    )
    # law tuning (the thesis fork's hard-coded numbers, named)
    follower_deadband_force: float = _nonneg(2.5, "N", "follower ignores smaller forces (decelerates)")
    follower_deadband_torque: float = _nonneg(2.5, "Nm", "same for torques")
    min_velocity_linear: float = param(
        0.005, unit="m/s", ge=0.0, shown_range=">= 0, < `max_velocity`",
        doc="commands of at most this magnitude become zero",
    )
    min_velocity_angular: float = param(
        0.005, unit="rad/s", ge=0.0, shown_range=">= 0, < the angular clamp", doc="same for rotations"
    )
    acceleration_linear: float = _pos(2.5, "m/s^2", "limit on speeding up")
    acceleration_angular: float = _pos(2.5, "rad/s^2", "same for rotations")
    deceleration_linear: float = _pos(2.5, "m/s^2", "limit on slowing down (fork: 0.005 m/s per 2 ms cycle)")
    deceleration_angular: float = _pos(2.5, "rad/s^2", "same for rotations")
    spring_output_scale: float = _pos(0.2, "", "spring velocity factor (fork: 0.2)")
    spring_rounding: float = _nonneg(0.01, "N, m/s", "spring rounds force and velocity to this step (0: off)")
    end_stop_time: float = _nonneg(
        0.05, "s", "a move that ends on its max travel (its normal end, not a fault) slows to rest over this "
        "long instead of stopping at once (0: at once; README, End conditions)",
    )
    compliant_slowdown_distance: float = _nonneg(0.02, "m", "compliant move slows down this near max travel")
    compliant_slowdown_angle: float = _nonneg(0.02, "rad", "same for rotations")
    compliant_approach_speed_linear: float = param(
        0.02, unit="m/s", gt=0.0, shown_range="> `min_velocity_linear`",
        doc="slowest compliant move speed when slowing down",
    )
    compliant_approach_speed_angular: float = param(
        0.02, unit="rad/s", gt=0.0, shown_range="> `min_velocity_angular`", doc="same for rotations"
    )
    compliant_default_velocity_linear: float = param(
        0.01, unit="m/s", gt=0.0, shown_range="> `min_velocity_linear`, <= `max_velocity`",
        doc="V_desired of a compliant move requested without one, toward its force limit's sign",
    )
    compliant_default_velocity_angular: float = param(
        0.05, unit="rad/s", gt=0.0, shown_range="> `min_velocity_angular`, <= the angular clamp",
        doc="same for rotations",
    )
    # exceeded_action move_away (after a move ended on a force/torque limit)
    move_away_velocity_linear: float = param(
        0.01, unit="m/s", gt=0.0, shown_range="> `min_velocity_linear`, <= `max_velocity`",
        doc="backing-off speed of `exceeded_action: move_away`, along the contact force",
    )
    move_away_velocity_angular: float = param(
        0.05, unit="rad/s", gt=0.0, shown_range="> `min_velocity_angular`, <= the angular clamp",
        doc="same for rotations",
    )
    move_away_release_fraction: float = param(
        0.5, gt=0.0, lt=1.0, unit="fraction of the axis's limit",
        doc="backing off ends once |F| is below this fraction of the axis's force/torque limit "
        "(hysteresis: it started at the limit)",
    )
    move_away_max_distance: float = _pos(
        0.02, "m", "backing off ends after this much commanded travel at the latest"
    )
    move_away_max_angle: float = _pos(0.2, "rad", "same for rotations")
    # force tracking law (ConfigureLaws FORCE_TRACKING)
    force_tracking_deadband_force: float = _nonneg(
        0.2, "N",
        "force tracking holds still while |F - target| is at most this (no deadband around zero force)",
    )
    force_tracking_deadband_torque: float = _nonneg(0.02, "Nm", "same for torques")
    force_tracking_contact_fraction: float = param(
        0.5, gt=0.0, le=1.0, unit="fraction of the target",
        doc="force tracking is out of contact, and approaches at its approach speed, while F is "
        "short of this fraction of the target",
    )
    force_tracking_fast_guard: bool = param(
        True, doc="force tracking never presses faster than (F_target - F) / b with F unfiltered once that F "
        "is in contact: a touch stops the pressing before the low-pass filter has seen it",
    )
    force_tracking_path_integral: float = _nonneg(
        1.0, "s", "beside a path law, force tracking adds integral action with this time constant: sliding "
        "carries the tool off a part it is a little tilted to, which the proportional law alone follows "
        "short of the target (README, Force tracking); 0: none"
    )
    # normal law (ConfigureLaws NORMAL on RX/RY; README, Keeping the tool normal)
    normal_min_force: float = _pos(
        3.0, "N", "the normal law reads the contact normal from |F| at or above this; below it the tool's "
        "orientation holds (no contact to read; a guess: `event_touch_force`'s value)"
    )
    normal_max_rate: float = _pos(
        0.15, "rad/s", "the followed normal turns at most this fast (a 0.25 m cylinder passed at 20 mm/s "
        "turns it 0.08 rad/s)"
    )
    normal_jump: float = _pos(
        0.2, "rad", "a normal estimate this far from the followed one (an edge, a landing elsewhere) is not "
        "followed: the orientation holds and ~status says so"
    )
    normal_friction: float = _nonneg(
        0.0, "", "the tool-surface sliding friction coefficient: the friction it predicts (mu |F| against "
        "the slide) is taken out of the force before the normal is read; 0: none assumed"
    )
    # path law (ConfigureLaws PATH, fed by ~path_reference)
    path_reference_timeout: float = _pos(
        0.5, "s", "a path law's move ends (PATH_LOST) when no ~path_reference came for this long (the tool "
        "stands still after `path_extrapolate`; a loaded 2-core machine stalled a replay's stream 0.26 s); a "
        "move set before its first reference waits this long for it, standing still"
    )
    path_extrapolate: float = _nonneg(
        0.05, "s", "a reference's position moves on with its velocity for at most this long after it came"
    )
    # contact events (~events) and hand-guiding (~guide)
    event_touch_force: float = _pos(
        3.0, "N", "|F| (preprocessed contact force, control frame) at which ~events reports a touch (above a "
        "UR e-series sensor's 0.2-0.6 N noise with margin; a guess for others)"
    )
    event_release_force: float = param(
        1.5, unit="N", ge=0.0, shown_range=">= 0, < `event_touch_force`",
        doc="|F| below which ~events reports the release (hysteresis)",
    )
    guide_axes: tuple[str, ...] = param(
        AXES, type="strings", shown_range="names of x, y, z, rx, ry, rz",
        doc="axes `~guide` makes followers when its request names none",
    )
    guide_damping_linear: float = _pos(
        50.0, "N/(m/s)", "hand-guiding follower damping b on X, Y, Z (a 10 N push: 0.2 m/s; a guess, tune "
        "per robot)"
    )
    guide_damping_angular: float = _pos(
        4.0, "Nm/(rad/s)", "same on RX, RY, RZ (a 2 Nm twist: 0.5 rad/s; a guess)"
    )
    guide_max_velocity_linear: float = _pos(
        0.25, "m/s", "hand-guiding speed cap on X, Y, Z (`max_velocity` still clamps)"
    )
    guide_max_velocity_angular: float = _pos(
        0.5, "rad/s", "same on RX, RY, RZ (the angular clamp still applies)"
    )
    guide_force_limit: float = _nonneg(
        0.0, "N", "hand-guiding ends on a force over this on a guided linear axis (0: only the global limits)"
    )
    guide_torque_limit: float = _nonneg(0.0, "Nm", "same for torques on guided rotational axes")
    guide_exceeded_action: int = param(
        0, choices=(0, 1, 2), doc="what a guided axis does after its limit: 0 stop, 1 move_away, 2 "
        "gravity_compensation (AxisLaw ACTION_*)",
    )
    diff_max_force: float = _nonneg(
        0.0, "N", "force change within `diff_window` that ends a move (force-jump end condition; 0: off)"
    )
    diff_max_torque: float = _nonneg(0.0, "Nm", "same for torques")
    diff_window: float = _pos(0.1, "s", "time window of the force-jump check")
    force_limit_arm_time: float = _nonneg(
        0.5, "s",
        "force/torque limits (FT_VIOLATION) are checked from this long after the axes start from rest (the "
        "law is set, or motion resumes after a safety hold), or once an axis has reached its law's velocity: "
        "a 1 kg tool speeding up at 0.5 m/s² reads 0.5 N on a wrist sensor, the thesis's whole limit. The "
        "law itself still slows down on contact meanwhile. 0 always checks, as the fork did",
    )

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
                self.force_tracking_path_integral,
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
            self.force_tracking_path_integral,
        )


@dataclass(frozen=True)
class AxisTuning:
    """Law tuning for one kind of axis (linear: N, m, m/s; angular: Nm, rad, rad/s).

    `ContactControlSettings.tuning` builds it from the parameters; the defaults are the linear parameters'.
    """

    deadband: float = ContactControlSettings.follower_deadband_force
    min_velocity: float = ContactControlSettings.min_velocity_linear
    acceleration: float = ContactControlSettings.acceleration_linear
    deceleration: float = ContactControlSettings.deceleration_linear
    max_velocity: float = ContactControlSettings.max_velocity
    slowdown: float = ContactControlSettings.compliant_slowdown_distance
    approach_speed: float = ContactControlSettings.compliant_approach_speed_linear
    diff_max: float = ContactControlSettings.diff_max_force
    spring_scale: float = ContactControlSettings.spring_output_scale
    spring_rounding: float = ContactControlSettings.spring_rounding
    default_velocity: float = ContactControlSettings.compliant_default_velocity_linear
    away_velocity: float = ContactControlSettings.move_away_velocity_linear
    away_max_travel: float = ContactControlSettings.move_away_max_distance
    track_deadband: float = ContactControlSettings.force_tracking_deadband_force
    contact_fraction: float = ContactControlSettings.force_tracking_contact_fraction
    track_integral_time: float = ContactControlSettings.force_tracking_path_integral


PARAMETERS = schema_of(ContactControlSettings)


#: Tuned live (dynamic_reconfigure, `dynparam set /contact_control_node KEY VALUE`): every change is checked
#: as at start-up (load_settings) and applied bumplessly (ContactControl.retune; the README's "Live tuning").
TUNABLE = (
    "max_velocity", "acceleration_linear", "deceleration_linear", "acceleration_angular",
    "deceleration_angular",
    "min_velocity_linear", "min_velocity_angular", "follower_deadband_force", "follower_deadband_torque",
    "force_tracking_deadband_force", "force_tracking_deadband_torque", "force_tracking_path_integral",
    "lp_filter_cutoff_freq",
    "global_max_force", "global_max_torque", "guide_damping_linear", "guide_damping_angular",
    "guide_max_velocity_linear", "guide_max_velocity_angular", "compliant_default_velocity_linear",
    "move_away_velocity_linear", "normal_min_force", "normal_max_rate", "normal_jump", "normal_friction",
    "spring_rounding",
)


def load_settings(params: ParamMap | None = None) -> ContactControlSettings:
    """Builds validated settings from a parameter dict.

    Args:
        params: the node's private parameters. Keys may also sit under a `contact_control` sub-dict, as in the
            original YAML; top-level keys win over nested ones. Missing keys take their defaults.

    Returns:
        The settings.

    Raises:
        ParamError: an unknown key (naming the closest valid one), a value of the wrong type or out of
            range, or a broken cross-constraint.
    """
    merged: dict[str, object] = {}
    params = dict(params or {})
    nested = params.pop("contact_control", None)
    if nested is not None:
        if not isinstance(nested, Mapping):
            raise ParamError("contact_control", "expected a dictionary of parameters")
        merged.update(nested)
    merged.update(params)
    try:
        values = PARAMETERS.load(merged)
    except SchemaError as err:
        raise ParamError(err.key, err.message) from None
    settings = PARAMETERS.build(ContactControlSettings, values)
    _check_cross_constraints(settings)
    return settings


def _check_cross_constraints(s: ContactControlSettings) -> None:
    """Relations between parameters (each one's own range is in its declaration)."""
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
    if s.event_release_force >= s.event_touch_force:
        raise ParamError("event_release_force", f"must be below event_touch_force {s.event_touch_force}")
    if not s.guide_axes or any(n not in AXES for n in s.guide_axes):
        raise ParamError("guide_axes", f"must name axes of {', '.join(AXES)}; got {list(s.guide_axes)}")
    if s.no_data_end_timeout and s.no_data_end_timeout < s.wrench_timeout:
        raise ParamError("no_data_end_timeout", "must be 0 or at least wrench_timeout")
