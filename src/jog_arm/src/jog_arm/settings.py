"""Typed, validated settings of the jog_arm server (the `jog_arm_server/*` parameters).

Parameters are read once at start-up into a frozen :class:`JogSettings`; every check names the key it
refuses, so a bad YAML file fails fast instead of moving the arm in a surprising way.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, fields

from compliant_common.errors import StackError
from compliant_common.schema import SchemaError, param, schema_of
from compliant_common.typedefs import ParamMap

from jog_arm.body_regions import OFF, REGIONS

__all__ = [
    "COMMAND_IN_TYPES",
    "COMMAND_OUT_TYPES",
    "INTEGRATE_FROM",
    "PARAMETERS",
    "TUNABLE",
    "JogSettings",
    "JointLimitOverride",
    "SettingsError",
    "flatten_params",
    "held_positions",
]

COMMAND_IN_TYPES = ("unitless", "speed_units")
COMMAND_OUT_TYPES = ("trajectory", "velocity_array")
INTEGRATE_FROM = ("commanded", "measured")

# Keys of MoveIt Servo / later jog_arm versions that users may carry over: warn and point at ours.
_RENAMED = {
    "lower_singularity_threshold": "singularity_threshold",
    "publish_period": "pub_period",
    "incoming_command_timeout": "incoming_cmd_timeout",
    "cartesian_command_in_topic": "cmd_in_topic",
    "command_out_topic": "cmd_out_topic",
    "robot_link_command_frame": "cmd_frame",
    "use_gazebo": "simu",
    "coll_check": None,
    "check_collisions": None,
    "contact_guard_exempt": "contact_cmd_in_topic",  # ours before: told contact_control apart by caller id
    "move_group_name": None,  # the fork's MoveIt group: the chain comes from planning_frame and ee_frame_name
}

# Keys read by the node only (not part of the motion law), accepted without warning.
_NODE_ONLY = ("robot_description",)
# Parameter trees read by the node only, each parsed by its own module (robot_stop: jog_arm.robot_stop).
_NODE_ONLY_TREES = ("robot_stop",)


class SettingsError(StackError):
    """A parameter is missing, has the wrong type or is out of range; the message names the key."""


@dataclass(frozen=True)
class JointLimitOverride:
    """Per-joint limits that replace the URDF's (None keeps the URDF value).

    Attributes:
        min_position: Lower position limit [rad or m].
        max_position: Upper position limit [rad or m].
        max_velocity: Velocity limit [rad/s or m/s].
        max_acceleration: Acceleration limit [rad/s² or m/s²] (URDFs carry none).
    """

    min_position: float | None = None
    max_position: float | None = None
    max_velocity: float | None = None
    max_acceleration: float | None = None


def _pos(default: float, unit: str, doc: str) -> float:
    return param(default, unit=unit, gt=0.0, doc=doc)


def _nonneg(default: float, unit: str, doc: str) -> float:
    return param(default, unit=unit, ge=0.0, doc=doc)


def _topic(default: str, doc: str = "") -> str:
    return param(default, nonempty=True, doc=doc)


@dataclass(frozen=True)
class JogSettings:
    """All jog_arm parameters, each declared once here (name, type, default, unit, range, doc).

    Build with :meth:`from_params`, which validates. Names are the 2018 fork's where it had one.
    """

    # --- the fork's parameters ---
    scale_linear: float = param(
        0.4, key="scale/linear", unit="m/s", gt=0.0,
        doc="speed of a unitless 1.0 (the fork's value was metres per publish period)",
    )
    scale_rotational: float = param(
        0.8, key="scale/rotational", unit="rad/s", gt=0.0, doc="angular speed of a unitless 1.0"
    )
    low_pass_filter_coeff: float = param(
        2.0, ge=1.0,
        doc="filter coefficient c: `y = (x + x₋₁ - (1-c) y₋₁)/(1+c)`, time constant ~c/2 cycles; larger "
        "smooths more (smaller than 1 makes the filter ring)",
    )
    joint_topic: str = _topic("joint_states", "sensor_msgs/JointState input")
    cmd_in_topic: str = _topic("jog_arm_server/delta_jog_cmds", "geometry_msgs/TwistStamped input")
    contact_cmd_in_topic: str = _topic(
        "jog_arm_server/contact_cmds", "geometry_msgs/TwistStamped input of contact_control's laws (two-node "
        "layout; contact_control's `velocity_out_topic`): not through the contact guard, its laws react to "
        "the force themselves"
    )
    cmd_frame: str = param(
        "", doc="frame of commands with an empty `header.frame_id`; `\"\"` = `planning_frame`"
    )
    incoming_cmd_timeout: float = _pos(
        1.0, "s",
        "no command this long: stop (0.3-5 in the fork; the robot packages use "
        "0.1)",
    )
    joint_state_timeout: float = _pos(
        0.2, "s", "no joint state this long: stop (STALE_JOINT_STATE); several periods of the state's rate"
    )
    cmd_out_topic: str = _topic("arm_controller/command", "joint command output (see `command_out_type`)")
    singularity_threshold: float = param(
        7.0, ge=1.0, doc="condition number where slowing starts"
    )
    hard_stop_singularity_threshold: float = param(
        12.0, shown_range=">= `singularity_threshold`", doc="condition number where motion stops"
    )
    singularity_length_scale: float = _pos(
        0.4, "m", "linear Jacobian rows are divided by it before the condition number (1.0 = raw)"
    )
    planning_frame: str = param(
        "base_link", nonempty=True,
        doc="URDF frame of the reported pose, the default command frame and tf lookups",
    )
    pub_period: float = _pos(0.01, "s", "control and publish period")
    simu: bool = param(False, doc="several trajectory points per message (`simu_points`)")
    # --- ours ---
    ee_frame_name: str = param("tool0", nonempty=True, doc="URDF frame commanded (tool centre point)")
    joint_names: tuple[str, ...] = param(
        (), type="strings", shown_range="no duplicates",
        doc="controlled joints in output order; `[]` = all joints from the root to `ee_frame_name`; others "
        "are locked (`held_joints`)",
    )
    held_joints: Mapping[str, float] = param(
        {}, type="any", unit="rad, m", shown_default="[]",
        doc="`[<joint>: position, ...]` of joints jog_arm never moves (a gripper, a head, another arm); "
        "joints neither controlled nor listed are held at 0 clamped into their limits. A list, so that "
        "loading a robot's file replaces an earlier robot's on the master",
    )
    command_in_type: str = param(
        "unitless", choices=COMMAND_IN_TYPES, doc="speed_units: m/s and rad/s, as contact_control sends"
    )
    command_out_type: str = param(
        "trajectory", choices=COMMAND_OUT_TYPES, doc="JointTrajectory or Float64MultiArray"
    )
    simu_points: int = param(5, ge=1, doc="points per trajectory in simu mode")
    num_outgoing_halt_msgs_to_publish: int = param(
        10, ge=1, doc="times the final zero command is sent"
    )
    joint_limit_margin: float = _nonneg(0.1, "rad", "distance kept from each revolute joint's position limit")
    joint_limit_slowdown_width: float = _nonneg(0.2, "rad", "ramp-down zone before the margin")
    # A rail's 0.1 m would be a tenth of its travel: prismatic joints have their own, in metres.
    prismatic_limit_margin: float = _nonneg(0.01, "m", "distance kept from each prismatic joint's limit")
    prismatic_slowdown_width: float = _nonneg(0.05, "m", "a prismatic joint's ramp-down zone")
    default_max_acceleration: float = _pos(
        3.0, "rad/s²", "for joints without an override (URDFs carry none)"
    )
    joint_limits: Mapping[str, JointLimitOverride] = param(
        {}, type="mapping", unit="rad, rad/s, rad/s²", shown_default="URDF",
        doc="per-joint overrides `<joint>: {min_position, max_position, max_velocity, max_acceleration}`; "
        "`max_velocity` is required for a joint whose URDF gives none (or 0), typically a continuous one; "
        "continuous joints have no position limits unless set here",
    )
    pinv_damping: float = _nonneg(0.02, "", "largest damping λ of the pseudo-inverse")
    pinv_damping_threshold: float = _nonneg(0.05, "", "smallest singular value below which damping starts")
    nullspace_gain: float = _nonneg(
        1.0, "1/s", "pull of the self-motion toward the posture (arms with > 6 joints)"
    )
    nullspace_posture: tuple[float, ...] = param(
        (), type="floats", unit="rad", shown_range="one per joint",
        doc="one value per joint; `[]` = posture when motion starts",
    )
    nullspace_joints: tuple[str, ...] = param(
        (), type="strings", shown_range="controlled joints",
        doc="the joints the pull moves toward `nullspace_posture` as a task of their own, the others go "
        "where the self-motion takes them (a rail kept near its middle: README, step 3); `[]` = every joint",
    )
    integrate_from: str = param(
        "commanded", choices=INTEGRATE_FROM,
        doc="reference of the next point; `commanded` only with `command_out_type` trajectory (a robot "
        "driven by velocities moves on over a late cycle, which a commanded reference does not)",
    )
    max_tracking_error: float = _nonneg(
        0.2, "rad", "commanded vs measured beyond this: restart from measured; 0 = never"
    )
    publish_on_command: bool = param(
        False,
        doc="also run a cycle (and publish) the moment a twist arrives, instead of waiting for the next "
        "timer tick; no timer then: a gap filler thread sleeps while twists come and runs a cycle 2.5 "
        "`pub_period` after the last twist-driven one, then one per `pub_period` until twists return "
        "(halting); a late or single missing twist gets no duplicate, older command. Lowest latency when "
        "commands come at about `1/pub_period` (contact_control)",
    )
    publish_synchronously: bool = param(
        False,
        doc="write the joint command to the subscribers' sockets inside the cycle instead of through rospy's "
        "sender thread per subscriber: about 90 µs less latency and less CPU, but a subscriber that stops "
        "reading (`rostopic echo | less`) then blocks the node's cycles, leaving a velocity controller "
        "without a watchdog on its last command. Turn on only when the robot side stops by itself when "
        "commands stop (the MuJoCo driver's `command_timeout`); the sim configs do",
    )
    # contact-force guard on twists from outside sources (keyboard, rostopic pub; see contact_guard.py)
    contact_guard_enabled: bool = param(
        True, doc="the [contact-force guard](#contact-force-guard) on outside twists"
    )
    contact_guard_max_force: float = _pos(20.0, "N", "motion into a contact stops at this contact force")
    contact_guard_slow_force: float = param(
        2.0, unit="N", ge=0.0, shown_range=">= 0, < `contact_guard_max_force`",
        doc="from this contact force motion into the contact is slowed",
    )
    contact_guard_slow_speed: float = _pos(
        0.01, "m/s", "into-contact speed cap at `contact_guard_slow_force`, falling to 0 at the max"
    )
    contact_guard_timeout: float = _pos(0.25, "s", "a contact force older than this stops outside twists")
    contact_guard_relief_speed: float = _pos(
        0.005, "m/s", "at the max force a push into the contact backs off at this instead"
    )
    contact_guard_wrench_topic: str = param(
        "contact_control_node/contact_wrench", doc="two-node layout: where the contact force comes from"
    )
    # the collaborative speed cap (ISO/TS 15066; speed_cap.py)
    collaborative_region: str = param(
        "hand", choices=(OFF, *REGIONS),
        doc="body region of ISO/TS 15066 the tip's speed is capped for, in the direction it moves (README: "
        "[collaborative speed cap](#collaborative-speed-cap)); `off`: no cap",
    )
    clamp_hold: float = _pos(
        0.05, "s", "a contact force at or over the region's quasi-static limit this long is a clamp (README: "
        "[clamping](#clamping)); shorter peaks (a strike) are not",
    )
    clamp_push_force: float = _pos(
        10.0, "N", "a contact force at or over this for clamp_hold while the contact guard holds a push into "
        "it back (slows or stops it) is a clamp (README: [clamping](#clamping))",
    )
    clamp_release_speed: float = _pos(0.02, "m/s", "a clamp is released backing off along the force at this")
    clamp_release_travel: float = _pos(
        0.05, "m", "a clamp's retreat stops after this far even if the force stays high (a stuck sensor) and "
        "says so (a guess: ten times the 3-4 mm a release takes on the simulated hand)",
    )
    contact_stop_scale: float = param(
        5.0, ge=1.0,
        doc="a push the contact guard stops at its limit, and a clamp, brake at this multiple of the joints' "
        "acceleration limits (README: [clamping](#clamping)); the driver's own limit still applies",
    )
    clamp_release_force: float = _pos(
        3.0, "N", "the release ends below this contact force (under 10 N with room for the force's error)"
    )
    collaborative_payload: float = param(
        0.0, unit="kg", ge=0.0,
        doc="mass at the tip that the URDF lacks (a grasped part), added to the arm's effective mass",
    )

    @classmethod
    def from_params(cls, params: ParamMap, prefix: str = "jog_arm_server/") -> JogSettings:
        """Builds and validates settings from a parameter dictionary.

        Args:
            params: Parameters as returned by ``rospy.get_param("~")`` (nested dicts) or flat keys with
                "/" (``{"scale/linear": 0.2}``). Missing keys take the defaults.
            prefix: Shown before key names in error messages.

        Returns:
            The validated settings.

        Raises:
            SettingsError: A key has a wrong type or value; the message names it.
        """
        settings, _ = cls.from_params_with_warnings(params, prefix)
        return settings

    @classmethod
    def from_params_with_warnings(
        cls, params: ParamMap, prefix: str = "jog_arm_server/"
    ) -> tuple[JogSettings, list[str]]:
        """Like :meth:`from_params`, also returning warnings about renamed keys (MoveIt Servo's)."""
        flat = flatten_params(params)
        warnings: list[str] = []
        given: dict[str, object] = {}
        for key in sorted(flat):
            base = key.split("/")[0]
            if base in _NODE_ONLY_TREES:
                continue
            if key in PARAMETERS or key in _NODE_ONLY or key.startswith(_NESTED):
                given[key] = flat[key]
            elif key in _RENAMED or base in _RENAMED:
                new = _RENAMED.get(key, _RENAMED.get(base))
                hint = f"use {prefix}{new}" if new else "not supported, ignored"
                warnings.append(f"{prefix}{key} is a renamed or unsupported key: {hint}")
            else:
                given[key] = flat[key]
        scalars = {k: v for k, v in given.items() if not k.startswith(_NESTED)}
        try:
            values = PARAMETERS.load(scalars, prefix, also_known=_NODE_ONLY)
        except SchemaError as err:
            raise SettingsError(_message(prefix, err)) from None
        values["joint_limits"] = _read_joint_limits(given, prefix)
        values["held_joints"] = held_positions(values.get("held_joints", []), f"{prefix}held_joints")
        settings = PARAMETERS.build(cls, values)
        settings.validate(prefix)
        return settings, warnings

    def validate(self, prefix: str = "jog_arm_server/") -> None:
        """Checks each parameter's range (its declaration) and the relations between parameters.

        Raises:
            SettingsError: Naming the first offending key.
        """
        try:
            PARAMETERS.check(PARAMETERS.values_of(self))
        except SchemaError as err:
            raise SettingsError(_message(prefix, err)) from None
        if self.hard_stop_singularity_threshold < self.singularity_threshold:
            raise SettingsError(
                f"{prefix}hard_stop_singularity_threshold ({self.hard_stop_singularity_threshold}) "
                f"must be >= {prefix}singularity_threshold ({self.singularity_threshold})"
            )
        if not self.contact_guard_slow_force < self.contact_guard_max_force:
            raise SettingsError(
                f"{prefix}contact_guard_slow_force must be below contact_guard_max_force "
                f"({self.contact_guard_max_force} N), got {self.contact_guard_slow_force}"
            )
        if not self.clamp_release_force < self.clamp_push_force:
            raise SettingsError(
                f"{prefix}clamp_release_force must be below clamp_push_force ({self.clamp_push_force} N), "
                f"got {self.clamp_release_force}: a released clamp would be one again at once"
            )
        if self.integrate_from == "commanded" and self.command_out_type == "velocity_array":
            # The robot holds a velocity over a late cycle; the commanded reference advances one pub_period
            # per cycle: it falls behind the arm (README, integrate_from).
            raise SettingsError(
                f"{prefix}integrate_from: commanded needs {prefix}command_out_type trajectory; with "
                "velocity_array set integrate_from: measured (the robot integrates the velocities itself, "
                "over the real time between commands, so a reference integrated over pub_period drifts "
                "from the arm whenever a cycle is late)"
            )
        if len(set(self.joint_names)) != len(self.joint_names):
            raise SettingsError(f"{prefix}joint_names has duplicates: {list(self.joint_names)}")
        posture, names = self.nullspace_posture, self.joint_names
        if posture and names and len(posture) != len(names):
            raise SettingsError(
                f"{prefix}nullspace_posture has {len(self.nullspace_posture)} values for "
                f"{len(self.joint_names)} joint_names"
            )

    def retuned(self, changed: Mapping[str, object], prefix: str = "jog_arm_server/") -> JogSettings:
        """These settings with `changed` (TUNABLE keys) checked as at start-up (live tuning).

        Raises:
            SettingsError: A key that is not tunable or a value out of its range, named.
        """
        for key in changed:
            if key not in TUNABLE:
                raise SettingsError(f"{prefix}{key} cannot be tuned live (tunable: {', '.join(TUNABLE)})")
        try:
            values = PARAMETERS.convert(changed)
        except SchemaError as err:
            raise SettingsError(_message(prefix, err)) from None
        settings = PARAMETERS.build(JogSettings, {**PARAMETERS.values_of(self), **values})
        settings.validate(prefix)
        return settings

    @property
    def default_cmd_frame(self) -> str:
        """Frame of commands whose header leaves the frame empty."""
        return self.cmd_frame or self.planning_frame


PARAMETERS = schema_of(JogSettings)

# What dynamic_reconfigure may change while the node runs (README, *Look and tune*): read per cycle or by
# parts that take a new value without a restart. Joint limits, periods, topics and frames are start-up only.
TUNABLE = (
    "scale/linear", "scale/rotational", "low_pass_filter_coeff", "incoming_cmd_timeout",
    "singularity_threshold", "hard_stop_singularity_threshold", "pinv_damping", "pinv_damping_threshold",
    "contact_guard_max_force", "contact_guard_slow_force", "contact_guard_slow_speed",
    "contact_guard_timeout", "contact_guard_relief_speed", "collaborative_region", "collaborative_payload",
    "clamp_hold", "clamp_push_force", "clamp_release_speed", "clamp_release_force", "clamp_release_travel",
)


def _message(prefix: str, err: SchemaError) -> str:
    """The schema's error with the key prefixed ("jog_arm_server/pub_period: must be > 0, got 0.0")."""
    if err.message.startswith(f"{prefix}{err.key} "):  # the unknown-key message names the key itself
        return err.message
    return f"{prefix}{err.key}: {err.message}"


# Per-joint mappings: flattened to "<key>/<joint>" and no further (a joint's limits stay one mapping).
_NESTED = ("joint_limits/",)


def flatten_params(params: ParamMap, base: str = "") -> dict[str, object]:
    """Flattens nested parameter dictionaries into "a/b" keys (flat keys pass through)."""
    flat: dict[str, object] = {}
    for key, value in params.items():
        name = f"{base}{str(key).strip('/')}"
        if isinstance(value, Mapping) and f"{name}/" in _NESTED:
            for joint, entry in value.items():
                flat[f"{name}/{joint}"] = entry
        elif isinstance(value, Mapping) and not name.startswith(_NESTED):
            flat.update(flatten_params(value, name + "/"))
        else:
            flat[name] = value
    return flat


def held_positions(value: object, key: str) -> dict[str, float]:
    """`held_joints` as written in YAML, a list of `<joint>: position` entries (a mapping is taken too).

    Raises:
        SettingsError: Not such a list, or a position that is not a finite number; the message names `key`.
    """
    entries = [value] if isinstance(value, Mapping) else value
    if not isinstance(entries, list | tuple) or not all(isinstance(e, Mapping) for e in entries):
        raise SettingsError(f"{key} must be a list of <joint>: position entries, got {value!r}")
    held: dict[str, float] = {}
    for entry in entries:
        for name, position in entry.items():
            number = isinstance(position, int | float) and not isinstance(position, bool)
            if not number or not math.isfinite(position):
                raise SettingsError(f"{key}/{name} must be a finite position [rad or m], got {position!r}")
            held[str(name)] = float(position)
    return held


def _read_joint_limits(flat: ParamMap, prefix: str) -> dict[str, JointLimitOverride]:
    limits: dict[str, JointLimitOverride] = {}
    allowed = {f.name for f in fields(JointLimitOverride)}
    for key, value in flat.items():
        if not key.startswith("joint_limits/"):
            continue
        joint = key[len("joint_limits/") :]
        if not isinstance(value, Mapping):
            raise SettingsError(f"{prefix}{key} must be a mapping of {sorted(allowed)}, got {value!r}")
        unknown = set(value) - allowed
        if unknown:
            raise SettingsError(
                f"{prefix}{key} has unknown keys {sorted(unknown)}; allowed: {sorted(allowed)}"
            )
        entry: dict[str, float | None] = {}
        for name in sorted(allowed):
            if name not in value:
                entry[name] = None
            elif isinstance(value[name], bool) or not isinstance(value[name], int | float) or not (
                math.isfinite(value[name])
            ):
                raise SettingsError(f"{prefix}{key}/{name} must be a finite number, got {value[name]!r}")
            else:
                entry[name] = float(value[name])
        override = JointLimitOverride(**entry)
        for name in ("max_velocity", "max_acceleration"):
            number = getattr(override, name)
            if number is not None and number <= 0.0:
                raise SettingsError(f"{prefix}{key}/{name} must be > 0, got {number}")
        if (
            override.min_position is not None
            and override.max_position is not None
            and override.min_position >= override.max_position
        ):
            raise SettingsError(f"{prefix}{key}: min_position must be < max_position")
        limits[joint] = override
    return limits
