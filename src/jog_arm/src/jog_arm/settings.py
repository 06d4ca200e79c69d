"""Typed, validated settings of the jog_arm server (the `jog_arm_server/*` parameters).

Parameters are read once at start-up into a frozen :class:`JogSettings`; every check names the key it
refuses, so a bad YAML file fails fast instead of moving the arm in a surprising way.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field, fields
from typing import Any

from compliant_common.keys import unknown_key_message

__all__ = [
    "COMMAND_IN_TYPES",
    "COMMAND_OUT_TYPES",
    "INTEGRATE_FROM",
    "JogSettings",
    "JointLimitOverride",
    "SettingsError",
    "flatten_params",
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
}

# Keys read by the node only (not part of the motion law), accepted without warning.
_NODE_ONLY = ("robot_description",)


class SettingsError(ValueError):
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


@dataclass(frozen=True)
class JogSettings:
    """All jog_arm parameters with their units. Build with :meth:`from_params`, which validates.

    Names are the 2018 fork's where it had one (see the package README for each key).
    """

    # --- the fork's parameters ---
    move_group_name: str = "manipulator"  # kept for compatibility; there is no MoveIt here
    scale_linear: float = 0.4  # [m/s] speed of a unitless command of 1.0
    scale_rotational: float = 0.8  # [rad/s] angular speed of a unitless command of 1.0
    low_pass_filter_coeff: float = 2.0  # [-] >= 1; larger smooths more
    joint_topic: str = "joint_states"
    cmd_in_topic: str = "jog_arm_server/delta_jog_cmds"
    cmd_frame: str = ""  # frame of commands whose header has none; "" = planning_frame
    incoming_cmd_timeout: float = 1.0  # [s]
    joint_state_timeout: float = 0.2  # [s] a joint state older than this halts (STALE_JOINT_STATE)
    cmd_out_topic: str = "arm_controller/command"
    singularity_threshold: float = 7.0  # [-] condition number where slowing starts
    hard_stop_singularity_threshold: float = 12.0  # [-] condition number where motion stops
    singularity_length_scale: float = 0.4  # [m] linear Jacobian rows are divided by it (1.0 = raw)
    planning_frame: str = "base_link"
    pub_period: float = 0.01  # [s]
    simu: bool = False
    # --- ours ---
    ee_frame_name: str = "tool0"
    joint_names: tuple[str, ...] = ()  # () = every joint from the root to ee_frame_name
    command_in_type: str = "unitless"
    command_out_type: str = "trajectory"
    simu_points: int = 5  # trajectory points per message in simu mode
    num_outgoing_halt_msgs_to_publish: int = 10
    joint_limit_margin: float = 0.1  # [rad] never closer to a position limit than this
    joint_limit_slowdown_width: float = 0.2  # [rad] ramp-down zone before the margin
    default_max_acceleration: float = 3.0  # [rad/s²] for joints without an override
    joint_limits: Mapping[str, JointLimitOverride] = field(default_factory=dict)
    pinv_damping: float = 0.02  # [-] largest damping of the pseudo-inverse
    pinv_damping_threshold: float = 0.05  # [-] smallest singular value below which damping starts
    nullspace_gain: float = 1.0  # [1/s] pull of the redundant motion toward the posture
    nullspace_posture: tuple[float, ...] = ()  # () = posture held when motion starts
    integrate_from: str = "commanded"
    max_tracking_error: float = 0.2  # [rad] re-sync to the measured state beyond this; 0 = never
    publish_on_command: bool = False  # also run a cycle when a twist arrives (lowest latency)
    publish_synchronously: bool = False  # write the command socket in the cycle's thread (no sender thread)
    # contact-force guard on twists from outside sources (keyboard, rostopic pub; see contact_guard.py)
    contact_guard_enabled: bool = True
    contact_guard_max_force: float = 20.0  # [N] motion into the contact stops at this contact force
    contact_guard_slow_force: float = 2.0  # [N] motion into the contact is slowed from this force on
    contact_guard_slow_speed: float = 0.01  # [m/s] into-contact speed cap at slow_force (0 at max_force)
    contact_guard_timeout: float = 0.25  # [s] an older contact force stops outside twists
    contact_guard_relief_speed: float = 0.005  # [m/s] at max_force a push into the contact backs off at this
    contact_guard_wrench_topic: str = "contact_control_node/contact_wrench"  # two-node layout's force input

    @classmethod
    def from_params(cls, params: Mapping[str, Any], prefix: str = "jog_arm_server/") -> JogSettings:
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
        cls, params: Mapping[str, Any], prefix: str = "jog_arm_server/"
    ) -> tuple[JogSettings, list[str]]:
        """Like :meth:`from_params`, also returning warnings about unknown or renamed keys."""
        flat = flatten_params(params)
        warnings: list[str] = []
        known = {_key_of(f.name) for f in fields(cls)}
        for key in sorted(flat):
            if key in known or key in _NODE_ONLY or key.startswith("joint_limits/"):
                continue
            base = key.split("/")[0]
            if key in _RENAMED or base in _RENAMED:
                new = _RENAMED.get(key, _RENAMED.get(base))
                hint = f"use {prefix}{new}" if new else "not supported, ignored"
                warnings.append(f"{prefix}{key} is a renamed or unsupported key: {hint}")
            else:
                raise SettingsError(unknown_key_message(key, known | set(_NODE_ONLY), prefix))

        reader = _Reader(flat, prefix)
        defaults = cls()
        values: dict[str, Any] = {}
        for f in fields(cls):
            key = _key_of(f.name)
            default = getattr(defaults, f.name)
            if f.name == "joint_limits":
                values[f.name] = _read_joint_limits(flat, prefix)
            elif isinstance(default, bool):
                values[f.name] = reader.boolean(key, default)
            elif isinstance(default, int):
                values[f.name] = reader.integer(key, default)
            elif isinstance(default, float):
                values[f.name] = reader.number(key, default)
            elif isinstance(default, str):
                values[f.name] = reader.text(key, default)
            elif f.name == "joint_names":
                values[f.name] = reader.names(key)
            elif f.name == "nullspace_posture":
                values[f.name] = reader.numbers(key)
        settings = cls(**values)
        settings.validate(prefix)
        return settings, warnings

    def validate(self, prefix: str = "jog_arm_server/") -> None:
        """Checks ranges and cross-constraints.

        Raises:
            SettingsError: Naming the first offending key.
        """

        def positive(name: str) -> None:
            if not getattr(self, name) > 0.0:
                raise SettingsError(f"{prefix}{_key_of(name)} must be > 0, got {getattr(self, name)}")

        def non_negative(name: str) -> None:
            if not getattr(self, name) >= 0.0:
                raise SettingsError(f"{prefix}{_key_of(name)} must be >= 0, got {getattr(self, name)}")

        for name in (
            "scale_linear",
            "scale_rotational",
            "incoming_cmd_timeout",
            "joint_state_timeout",
            "pub_period",
            "singularity_threshold",
            "singularity_length_scale",
            "default_max_acceleration",
        ):
            positive(name)
        for name in (
            "joint_limit_margin",
            "joint_limit_slowdown_width",
            "pinv_damping",
            "pinv_damping_threshold",
            "nullspace_gain",
            "max_tracking_error",
        ):
            non_negative(name)
        if self.num_outgoing_halt_msgs_to_publish < 1:
            raise SettingsError(
                f"{prefix}num_outgoing_halt_msgs_to_publish must be >= 1 (the final zero command is sent "
                f"that many times), got {self.num_outgoing_halt_msgs_to_publish}"
            )
        if self.singularity_threshold < 1.0:
            raise SettingsError(
                f"{prefix}singularity_threshold must be >= 1 (a condition number), "
                f"got {self.singularity_threshold}"
            )
        if self.hard_stop_singularity_threshold < self.singularity_threshold:
            raise SettingsError(
                f"{prefix}hard_stop_singularity_threshold ({self.hard_stop_singularity_threshold}) "
                f"must be >= {prefix}singularity_threshold ({self.singularity_threshold})"
            )
        if self.low_pass_filter_coeff < 1.0:
            raise SettingsError(
                f"{prefix}low_pass_filter_coeff must be >= 1 (smaller values make the filter ring), "
                f"got {self.low_pass_filter_coeff}"
            )
        for name in ("contact_guard_max_force", "contact_guard_slow_speed", "contact_guard_timeout",
                     "contact_guard_relief_speed"):
            positive(name)
        if not 0.0 <= self.contact_guard_slow_force < self.contact_guard_max_force:
            raise SettingsError(
                f"{prefix}contact_guard_slow_force must be >= 0 and below contact_guard_max_force "
                f"({self.contact_guard_max_force} N), got {self.contact_guard_slow_force}"
            )
        if self.simu_points < 1:
            raise SettingsError(f"{prefix}simu_points must be >= 1, got {self.simu_points}")
        for name, allowed in (
            ("command_in_type", COMMAND_IN_TYPES),
            ("command_out_type", COMMAND_OUT_TYPES),
            ("integrate_from", INTEGRATE_FROM),
        ):
            if getattr(self, name) not in allowed:
                raise SettingsError(f"{prefix}{name} must be one of {allowed}, got {getattr(self, name)!r}")
        for name in ("ee_frame_name", "planning_frame", "cmd_in_topic", "cmd_out_topic", "joint_topic"):
            if not getattr(self, name):
                raise SettingsError(f"{prefix}{name} must not be empty")
        if len(set(self.joint_names)) != len(self.joint_names):
            raise SettingsError(f"{prefix}joint_names has duplicates: {list(self.joint_names)}")
        posture, names = self.nullspace_posture, self.joint_names
        if posture and names and len(posture) != len(names):
            raise SettingsError(
                f"{prefix}nullspace_posture has {len(self.nullspace_posture)} values for "
                f"{len(self.joint_names)} joint_names"
            )

    @property
    def default_cmd_frame(self) -> str:
        """Frame of commands whose header leaves the frame empty."""
        return self.cmd_frame or self.planning_frame


def _key_of(field_name: str) -> str:
    """Parameter key of a settings field (the `scale/*` pair is nested like the fork's YAML)."""
    nested = {"scale_linear": "scale/linear", "scale_rotational": "scale/rotational"}
    return nested.get(field_name, field_name)


def flatten_params(params: Mapping[str, Any], base: str = "") -> dict[str, Any]:
    """Flattens nested parameter dictionaries into "a/b" keys (flat keys pass through)."""
    flat: dict[str, Any] = {}
    for key, value in params.items():
        name = f"{base}{str(key).strip('/')}"
        if isinstance(value, Mapping) and name != "joint_limits" and not name.startswith("joint_limits/"):
            flat.update(flatten_params(value, name + "/"))
        elif isinstance(value, Mapping) and name == "joint_limits":
            for joint, limits in value.items():
                flat[f"joint_limits/{joint}"] = limits
        else:
            flat[name] = value
    return flat


class _Reader:
    """Typed access to flat parameters with errors that name the key."""

    def __init__(self, flat: Mapping[str, Any], prefix: str) -> None:
        self._flat = flat
        self._prefix = prefix

    def _get(self, key: str, default: Any) -> Any:
        return self._flat.get(key, default)

    def number(self, key: str, default: float) -> float:
        value = self._get(key, default)
        if isinstance(value, bool) or not isinstance(value, int | float) or not math.isfinite(value):
            raise SettingsError(f"{self._prefix}{key} must be a finite number, got {value!r}")
        return float(value)

    def integer(self, key: str, default: int) -> int:
        value = self._get(key, default)
        if isinstance(value, bool) or not isinstance(value, int):
            raise SettingsError(f"{self._prefix}{key} must be an integer, got {value!r}")
        return value

    def boolean(self, key: str, default: bool) -> bool:
        value = self._get(key, default)
        if not isinstance(value, bool):
            raise SettingsError(f"{self._prefix}{key} must be true or false, got {value!r}")
        return value

    def text(self, key: str, default: str) -> str:
        value = self._get(key, default)
        if not isinstance(value, str):
            raise SettingsError(f"{self._prefix}{key} must be a string, got {value!r}")
        return value

    def names(self, key: str) -> tuple[str, ...]:
        value = self._get(key, [])
        if not isinstance(value, list | tuple) or not all(isinstance(v, str) and v for v in value):
            raise SettingsError(f"{self._prefix}{key} must be a list of joint names, got {value!r}")
        return tuple(value)

    def numbers(self, key: str) -> tuple[float, ...]:
        value = self._get(key, [])
        if not isinstance(value, list | tuple) or not all(
            isinstance(v, int | float) and not isinstance(v, bool) and math.isfinite(v) for v in value
        ):
            raise SettingsError(f"{self._prefix}{key} must be a list of finite numbers, got {value!r}")
        return tuple(float(v) for v in value)


def _read_joint_limits(flat: Mapping[str, Any], prefix: str) -> dict[str, JointLimitOverride]:
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
        reader = _Reader(dict(value), f"{prefix}{key}/")
        entry = {name: reader.number(name, 0.0) if name in value else None for name in allowed}
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
