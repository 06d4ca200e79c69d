"""Driver interface profiles: how the simulated robot speaks so that it looks like a given real driver.

Pure (no ROS). A profile is a YAML file (``config/profiles/<name>.yaml``, or any path) naming the real
driver's topics, frames, rates, wrench convention, controllers and reflex; the node
(``~profile``, ``~profile_options``) applies it. Options are the user's knobs a real driver has as launch
arguments (the controller generation, the state controller's ``publish_rate`` and ``arm_id``; see the
profiles' YAML):

* ``options``: the defaults; users may set only these keys;
* an option named like a top-level key sets that key (``publish_rate``);
* ``variants: {option: {value: {key: value, ...}}}``: an option's value selects overrides
  (``series: e_series`` -> ``publish_rate: 500``; a mapping such as ``wrench`` is merged key by key);
* every string may use ``{option}`` placeholders (``"{arm_id}_K"``); a value that is one placeholder alone
  takes the option's value as it is (``force_thresholds: "{reflex_force_thresholds}"``: a list);
* ``option_params: {option: parameter}``: the parameter the real driver reads that option from (a state
  controller's ``publish_rate``); the node takes it from the parameter server when the user's
  options do not set it, so a robot package's driver configuration reaches the emulation as it reaches the
  real driver.
"""

from __future__ import annotations

import dataclasses
import functools
import math
import os
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

import yaml
from compliant_common.errors import StackError

from mujoco_driver.controllers import ControllerError, ControllerSpec

__all__ = ["DriverProfile", "FrameLink", "ProfileError", "ProtectiveStopSpec", "ReflexSpec", "RobotStateSpec",
           "WrenchSpec",
           "known_profiles", "load_profile", "option_params", "profile_path", "variant_options"]

PROFILE_DIR = os.path.join(os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))),
                           "config", "profiles")
_MODELS = ("sensor", "payload_compensated", "external_estimate", "current_estimate")
_WEIGHT_REMOVED = _MODELS[1:]  # the models that subtract a payload's weight
_FROM_JOINT_TORQUES = ("external_estimate", "current_estimate")


class ProfileError(StackError):
    """A profile cannot be found or is invalid; the message names the file and the key."""


@dataclass(frozen=True)
class WrenchSpec:
    """How the wrench goes out.

    Attributes:
        topic: geometry_msgs/WrenchStamped topic.
        frame: Its header.frame_id (a tf frame the profile's ``tf`` or the description provides).
        frame_link: URDF link with the frame's origin and axes (the wrench is transformed into it).
        model: ``sensor`` (raw wrist sensor: tool weight included), ``payload_compensated`` (the tool's
            weight removed, as a controller that knows its payload), ``external_estimate`` (a model-based
            estimate from joint torques: weight removed) or ``current_estimate`` (from motor currents: weight
            removed, low-pass filtered by ``lag``).
        sign: +1: the wrench the environment exerts on the tool; -1: its opposite (the wrench the robot
            exerts on the environment).
        offset_force, offset_torque: Amplitude of the configuration-dependent offset [N, Nm].
        offset_scale: Joint-space frequency of the offset [1/rad]: how fast it changes with the configuration
            (also that of ``torque_error``).
        payload_mass_error: The payload mass set on the robot minus the true tool's [kg]: the driver removes
            the set payload's weight, so the published wrench carries minus the difference's weight (+0.3 kg:
            +2.9 N against gravity, turning with the tool). Models that remove a weight only.
        payload_com_error: The set payload's centre of mass minus the true tool's, in the wrench frame [m].
        torque_error: Amplitude per joint of a joint-torque model error [Nm] that changes smoothly with the
            configuration; an estimate from joint torques turns it into a wrench error through the wrench
            frame's Jacobian. ``external_estimate`` and ``current_estimate`` only.
        noise_force, noise_torque: Standard deviation of the white noise [N, Nm], one for all three axes or
            one per axis.
        drift_force, drift_torque: Stationary standard deviation of the slow drift (AR(1)) [N, Nm], idem.
        drift_time_constant: The drift's correlation time [s] (0: no drift).
        lag: Time constant of the first-order filter on the value [s] (0: none).
        period_mean: The value is the mean of the simulated sensor's wrench over the publication period
            (every physics step since the last publication), not its value at the publishing step: a driver
            that estimates the wrench at a faster rate than it publishes, from filtered signals, carries no
            alias of the contact's faster ringing.
        contact_shift_threshold: A contact force above this [N] shifts the zero once released (0: never).
        contact_shift_fraction: The shift's size as a fraction of the contact's peak force.
        seed: Random seed of the offset's shape, the noise, the drift and the shifts.
        zero_service: std_srvs/Trigger service that zeroes the wrench ("" = none).
    """

    topic: str
    frame: str
    frame_link: str
    model: str = "sensor"
    sign: float = 1.0
    offset_force: float = 0.0
    offset_torque: float = 0.0
    offset_scale: float = 0.5
    payload_mass_error: float = 0.0
    payload_com_error: tuple[float, float, float] = (0.0, 0.0, 0.0)
    torque_error: float = 0.0
    noise_force: float | tuple[float, ...] = 0.0
    noise_torque: float | tuple[float, ...] = 0.0
    drift_force: float | tuple[float, ...] = 0.0
    drift_torque: float | tuple[float, ...] = 0.0
    drift_time_constant: float = 0.0
    lag: float = 0.0
    period_mean: bool = False
    contact_shift_threshold: float = 0.0
    contact_shift_fraction: float = 0.0
    seed: int = 0
    zero_service: str = ""


@dataclass(frozen=True)
class FrameLink:
    """A tf transform the driver publishes: ``child`` in ``parent``, which is where URDF link
    ``child_link`` is relative to URDF link ``parent_link`` (the same link twice: identity)."""

    parent: str
    child: str
    parent_link: str
    child_link: str


@dataclass(frozen=True)
class ReflexSpec:
    """A collision reflex: the arm stops when a component of the published wrench's magnitude exceeds its
    threshold, and takes no motion until the recovery action is called.

    Attributes:
        force_thresholds: [fx, fy, fz, tx, ty, tz] [N, Nm].
        recovery_action: Name of the recovery action (an empty goal).
        recovery_type: Its ``package/NameAction``.
        state: The robot state message that reports the reflex (None: none).
    """

    force_thresholds: tuple[float, ...]
    recovery_action: str
    recovery_type: str
    state: RobotStateSpec | None = None


@dataclass(frozen=True)
class RobotStateSpec:
    """A driver's robot state message, published with each joint state; the emulation fills the fields
    named here and leaves the others at their defaults.

    Attributes:
        topic, type: Where and what (``package/Message``).
        mode_field: The robot mode's field; ``moving`` and ``stopped``: its values while the arm takes
            commands and while the reflex holds it; ``running``: every value a real robot reports while it
            takes commands (what a stack watching the mode accepts; ``make robot`` writes it).
        joints, velocities: Fixed-size arrays of the joint positions and velocities (the arm's, then zeros).
        wrench: The 6-array of the published wrench.
        held_flags: Boolean fields (dotted paths) true while the reflex holds the arm.
        tripped_flags: Boolean fields true once it tripped (the last motion's errors).
    """

    topic: str
    type: str
    mode_field: str
    moving: int
    stopped: int
    joints: str
    velocities: str
    wrench: str
    running: tuple[int, ...]
    held_flags: tuple[str, ...] = ()
    tripped_flags: tuple[str, ...] = ()


@dataclass(frozen=True)
class ProtectiveStopSpec:
    """A UR-style protective stop (:mod:`mujoco_driver.protective_stop`) and the driver's names for it.

    Attributes:
        force_limit: The safety configuration's TCP force limit [N].
        unlock_after: Seconds after the stop before the dashboard accepts an unlock.
        safety_mode_topic: ur_dashboard_msgs/SafetyMode topic (latched).
        robot_mode_topic: ur_dashboard_msgs/RobotMode topic (latched).
        program_running_topic: std_msgs/Bool topic (latched): the External Control program runs.
        unlock_service: std_srvs/Trigger service that releases the protective stop.
        play_services: std_srvs/Trigger services that start the program again.
    """

    force_limit: float
    unlock_after: float
    safety_mode_topic: str
    robot_mode_topic: str
    program_running_topic: str
    unlock_service: str
    play_services: tuple[str, ...]


@dataclass(frozen=True)
class DriverProfile:
    """A driver's interface, resolved from its YAML and the user's options.

    Attributes:
        driver: The real driver's name (for logs).
        publish_rate: Rate of joint_states, the wrench, tf and speed scaling [Hz].
        joint_states_topic: sensor_msgs/JointState topic.
        wrench: See :class:`WrenchSpec`.
        tf: Transforms published on /tf with the state.
        controller_manager: Namespace of the controller manager services.
        controllers: The loaded controllers (command topic: ``<name>/command``).
        speed_scaling_topic: std_msgs/Float64 topic of the speed scaling factor ("" = none).
        reflex: See :class:`ReflexSpec` (None = none).
        protective_stop: See :class:`ProtectiveStopSpec` (None = none).
        options: The resolved options.
    """

    driver: str
    publish_rate: float
    joint_states_topic: str
    wrench: WrenchSpec
    tf: tuple[FrameLink, ...] = ()
    controller_manager: str = "controller_manager"
    controllers: tuple[ControllerSpec, ...] = ()
    speed_scaling_topic: str = ""
    reflex: ReflexSpec | None = None
    protective_stop: ProtectiveStopSpec | None = None
    options: Mapping[str, Any] = field(default_factory=dict)

    def publish_steps(self, dt: float) -> float:
        """Simulation steps per publication (fractional: the node keeps the average rate exact)."""
        return max(1.0, 1.0 / (self.publish_rate * dt))

    def links(self) -> set[str]:
        """Every URDF link the profile needs (checked against the description by the node)."""
        names = {self.wrench.frame_link}
        for t in self.tf:
            names.update((t.parent_link, t.child_link))
        return names


def known_profiles() -> list[str]:
    """The profile names in ``config/profiles`` (sorted)."""
    if not os.path.isdir(PROFILE_DIR):
        return []
    return sorted(f[:-5] for f in os.listdir(PROFILE_DIR) if f.endswith(".yaml"))


def profile_path(name_or_path: str) -> str:
    """The YAML file of a profile name (``config/profiles/<name>.yaml``) or a path.

    Raises:
        ProfileError: If there is no such file (the message lists the profiles there are).
    """
    if os.sep in name_or_path or name_or_path.endswith((".yaml", ".yml")):
        path = name_or_path
    else:
        path = os.path.join(PROFILE_DIR, f"{name_or_path}.yaml")
    if not os.path.isfile(path):
        raise ProfileError(f"driver profile {name_or_path!r}: no file {path} (profiles: {known_profiles()})")
    return path


def _format(value: Any, options: Mapping[str, Any], where: str) -> Any:
    if isinstance(value, str) and value.startswith("{") and value.endswith("}") and value[1:-1] in options:
        return options[value[1:-1]]  # a whole-value placeholder keeps the option's type (a list, a number)
    if isinstance(value, str):
        try:
            return value.format_map(options)
        except (KeyError, ValueError) as exc:
            raise ProfileError(f"{where}: placeholder in {value!r} is not an option ({exc})") from None
    if isinstance(value, Mapping):
        return {k: _format(v, options, f"{where}.{k}") for k, v in value.items()}
    if isinstance(value, list):
        return [_format(v, options, f"{where}[{i}]") for i, v in enumerate(value)]
    return value


def _number(data: Mapping[str, Any], key: str, where: str, default: float | None = None,
            positive: bool = False) -> float:
    value = data.get(key, default)
    if value is None:
        raise ProfileError(f"{where}.{key}: missing")
    if isinstance(value, bool) or not isinstance(value, int | float) or not math.isfinite(value):
        raise ProfileError(f"{where}.{key}: expected a finite number, got {value!r}")
    if positive and value <= 0.0:
        raise ProfileError(f"{where}.{key}: must be > 0, got {value}")
    if value < 0.0:
        raise ProfileError(f"{where}.{key}: must be >= 0, got {value}")
    return float(value)


def _signed(value: Any, where: str) -> float:
    """A finite number of either sign."""
    if isinstance(value, bool) or not isinstance(value, int | float) or not math.isfinite(value):
        raise ProfileError(f"{where}: expected a finite number, got {value!r}")
    return float(value)


def _vector3(data: Mapping[str, Any], key: str, where: str) -> tuple[float, float, float]:
    """Three finite numbers [x, y, z] of either sign (default zeros)."""
    value = data.get(key, [0.0, 0.0, 0.0])
    if not isinstance(value, list | tuple) or len(value) != 3:
        raise ProfileError(f"{where}.{key}: expected three numbers [x, y, z], got {value!r}")
    x, y, z = (_signed(v, f"{where}.{key}") for v in value)
    return x, y, z


def _per_axis(data: Mapping[str, Any], key: str, where: str) -> float | tuple[float, ...]:
    """A number >= 0 for three axes, or a list of three."""
    value = data.get(key, 0.0)
    if isinstance(value, list):
        if len(value) != 3:
            raise ProfileError(f"{where}.{key}: expected one number or three [x, y, z], got {value!r}")
        return tuple(_number({key: v}, key, where) for v in value)
    return _number(data, key, where, 0.0)


def _flag(data: Mapping[str, Any], key: str, where: str) -> bool:
    value = data.get(key, False)
    if not isinstance(value, bool):
        raise ProfileError(f"{where}.{key}: true or false, got {value!r}")
    return value


def _string(data: Mapping[str, Any], key: str, where: str, default: str | None = None) -> str:
    value = data.get(key, default)
    if value is None or not isinstance(value, str) or (default is None and not value):
        raise ProfileError(f"{where}.{key}: expected a non-empty string, got {value!r}")
    return value


def _read(path: str) -> Mapping[str, Any]:
    try:
        with open(path) as stream:
            raw = yaml.safe_load(stream)
    except (OSError, yaml.YAMLError) as exc:
        raise ProfileError(f"driver profile {path}: cannot read: {exc}") from None
    if not isinstance(raw, Mapping):
        raise ProfileError(f"driver profile {path}: expected a mapping")
    return raw


def option_params(name_or_path: str) -> dict[str, str]:
    """The parameters the real driver reads options from: {option: parameter name} (see the module docstring).

    Raises:
        ProfileError: No such profile, or an entry that is not an option name mapped to a parameter name.
    """
    path = profile_path(name_or_path)
    raw = _read(path)
    entries = raw.get("option_params") or {}
    options = raw.get("options") or {}
    where = f"{os.path.basename(path)}.option_params"
    if not isinstance(entries, Mapping):
        raise ProfileError(f"{where}: expected a mapping {{option: parameter}}")
    for option, name in entries.items():
        if option not in options or not isinstance(name, str) or not name:
            raise ProfileError(f"{where}.{option}: must be an option ({sorted(options)}) mapped to a "
                               "parameter name")
    return dict(entries)


def variant_options(name_or_path: str) -> list[dict[str, Any]]:
    """The options of each variant the profile offers, one option at a time (the others at their defaults),
    e.g. [{"series": "cb3"}, {"series": "e_series"}, ...]; [{}] for a profile without variants.

    Raises:
        ProfileError: If there is no such profile file or it is not valid YAML.
    """
    raw = _read(profile_path(name_or_path))
    out = [{option: value} for option, choices in (raw.get("variants") or {}).items() for value in choices]
    return out or [{}]


def _check_model_errors(wrench: WrenchSpec, where: str) -> None:
    """Refuse an error the model cannot have (a raw sensor removes no payload; only an estimate from joint
    torques has a joint-torque model error)."""
    payload = {"payload_mass_error": wrench.payload_mass_error != 0.0,
               "payload_com_error": any(wrench.payload_com_error)}
    for key, nonzero in payload.items():
        if nonzero and wrench.model not in _WEIGHT_REMOVED:
            raise ProfileError(f"{where}.{key}: only for a model that removes the payload's weight "
                               f"{_WEIGHT_REMOVED}, not {wrench.model!r} (a raw sensor reads the true tool)")
    if wrench.torque_error and wrench.model not in _FROM_JOINT_TORQUES:
        raise ProfileError(f"{where}.torque_error: only for a wrench estimated from joint torques "
                           f"{_FROM_JOINT_TORQUES}, not {wrench.model!r}")


def _section(data: Any, spec: type, where: str) -> Mapping[str, Any] | None:
    """An optional mapping whose keys are those of dataclass ``spec`` (None: absent)."""
    if data is None:
        return None
    if not isinstance(data, Mapping):
        raise ProfileError(f"{where}: expected a mapping")
    unknown = set(data) - {f.name for f in dataclasses.fields(spec)}
    if unknown:
        raise ProfileError(f"{where}: unknown keys {sorted(unknown)}")
    return data


def _robot_state(section: Any, where: str) -> RobotStateSpec | None:
    data = _section(section, RobotStateSpec, where)
    if data is None:
        return None
    flags: dict[str, tuple[str, ...]] = {}
    for key in ("held_flags", "tripped_flags"):
        value = data.get(key, [])
        if not (isinstance(value, list) and all(isinstance(v, str) and v for v in value)):
            raise ProfileError(f"{where}.{key}: expected a list of field names, got {value!r}")
        flags[key] = tuple(value)
    modes: dict[str, int] = {}
    for key in ("moving", "stopped"):
        value = data.get(key)
        if isinstance(value, bool) or not isinstance(value, int):
            raise ProfileError(f"{where}.{key}: expected the robot mode's integer value, got {value!r}")
        modes[key] = value
    running = data.get("running", [modes["moving"]])
    if not (isinstance(running, list) and running and modes["moving"] in running
            and all(isinstance(v, int) and not isinstance(v, bool) for v in running)):
        raise ProfileError(f"{where}.running: expected a list of robot modes that includes `moving`, "
                           f"got {running!r}")
    name = functools.partial(_string, data, where=where)
    return RobotStateSpec(
        topic=name("topic"), type=name("type"), mode_field=name("mode_field"), moving=modes["moving"],
        stopped=modes["stopped"], joints=name("joints"), velocities=name("velocities"), wrench=name("wrench"),
        running=tuple(running), held_flags=flags["held_flags"], tripped_flags=flags["tripped_flags"])


def _protective_stop(section: Any, where: str) -> ProtectiveStopSpec | None:
    data = _section(section, ProtectiveStopSpec, where)
    if data is None:
        return None
    plays = data.get("play_services")
    if not (isinstance(plays, list) and plays and all(isinstance(p, str) and p for p in plays)):
        raise ProfileError(f"{where}.play_services: expected a list of service names, got {plays!r}")
    return ProtectiveStopSpec(
        force_limit=_number(data, "force_limit", where, positive=True),
        unlock_after=_number(data, "unlock_after", where, 0.0),
        safety_mode_topic=_string(data, "safety_mode_topic", where),
        robot_mode_topic=_string(data, "robot_mode_topic", where),
        program_running_topic=_string(data, "program_running_topic", where),
        unlock_service=_string(data, "unlock_service", where),
        play_services=tuple(plays),
    )


def load_profile(name_or_path: str, options: Mapping[str, Any] | None = None) -> DriverProfile:
    """Read, resolve and validate a profile.

    Args:
        name_or_path: A profile name (``ur_robot_driver``) or a YAML path.
        options: The user's options (keys must be among the profile's ``options``).

    Raises:
        ProfileError: Naming the file and the bad key.
    """
    path = profile_path(name_or_path)
    raw = _read(path)
    where = os.path.basename(path)
    resolved = dict(raw.get("options") or {})
    for key, value in (options or {}).items():
        if key not in resolved:
            raise ProfileError(f"{where}: unknown option {key!r} (options: {sorted(resolved)})")
        resolved[key] = value
    data = {k: v for k, v in raw.items() if k not in ("options", "variants", "option_params")}
    for option, choices in (raw.get("variants") or {}).items():
        value = resolved.get(option)
        if value not in choices:
            raise ProfileError(f"{where}: option {option}={value!r} must be one of {sorted(choices)}")
        for key, override in choices[value].items():  # a mapping (wrench) is merged key by key
            merge = isinstance(override, Mapping) and isinstance(data.get(key), Mapping)
            data[key] = {**data[key], **override} if merge else override
    for key, value in resolved.items():
        if key in data:
            data[key] = value
    data = _format(data, resolved, where)

    known = {"driver", "publish_rate", "joint_states_topic", "wrench", "tf", "controller_manager",
             "controllers", "speed_scaling_topic", "reflex", "protective_stop"}
    unknown = set(data) - known
    if unknown:
        raise ProfileError(f"{where}: unknown keys {sorted(unknown)} (known: {sorted(known)})")
    w = data.get("wrench")
    if not isinstance(w, Mapping):
        raise ProfileError(f"{where}.wrench: expected a mapping")
    wrench_keys = set(WrenchSpec.__dataclass_fields__)
    if set(w) - wrench_keys:
        raise ProfileError(f"{where}.wrench: unknown keys {sorted(set(w) - wrench_keys)}")
    model = w.get("model", "sensor")
    if model not in _MODELS:
        raise ProfileError(f"{where}.wrench.model: one of {_MODELS}, got {model!r}")
    sign = w.get("sign", 1)
    if sign not in (1, -1):
        raise ProfileError(f"{where}.wrench.sign: 1 or -1, got {sign!r}")
    wrench = WrenchSpec(
        topic=_string(w, "topic", f"{where}.wrench"),
        frame=_string(w, "frame", f"{where}.wrench"),
        frame_link=_string(w, "frame_link", f"{where}.wrench"),
        model=model,
        sign=float(sign),
        offset_force=_number(w, "offset_force", f"{where}.wrench", 0.0),
        offset_torque=_number(w, "offset_torque", f"{where}.wrench", 0.0),
        offset_scale=_number(w, "offset_scale", f"{where}.wrench", 0.5),
        payload_mass_error=_signed(w.get("payload_mass_error", 0.0), f"{where}.wrench.payload_mass_error"),
        payload_com_error=_vector3(w, "payload_com_error", f"{where}.wrench"),
        torque_error=_number(w, "torque_error", f"{where}.wrench", 0.0),
        noise_force=_per_axis(w, "noise_force", f"{where}.wrench"),
        noise_torque=_per_axis(w, "noise_torque", f"{where}.wrench"),
        drift_force=_per_axis(w, "drift_force", f"{where}.wrench"),
        drift_torque=_per_axis(w, "drift_torque", f"{where}.wrench"),
        drift_time_constant=_number(w, "drift_time_constant", f"{where}.wrench", 0.0),
        lag=_number(w, "lag", f"{where}.wrench", 0.0),
        period_mean=_flag(w, "period_mean", f"{where}.wrench"),
        contact_shift_threshold=_number(w, "contact_shift_threshold", f"{where}.wrench", 0.0),
        contact_shift_fraction=_number(w, "contact_shift_fraction", f"{where}.wrench", 0.0),
        seed=int(_number(w, "seed", f"{where}.wrench", 0)),
        zero_service=_string(w, "zero_service", f"{where}.wrench", ""),
    )
    _check_model_errors(wrench, f"{where}.wrench")
    tf = []
    for i, entry in enumerate(data.get("tf") or []):
        at = f"{where}.tf[{i}]"
        if not isinstance(entry, Mapping):
            raise ProfileError(f"{at}: expected a mapping")
        keys = ("parent", "child", "parent_link", "child_link")
        tf.append(FrameLink(*(_string(entry, k, at) for k in keys)))
    try:
        controllers = tuple(ControllerSpec.from_dict(c) for c in data.get("controllers") or [])
    except ControllerError as exc:
        raise ProfileError(f"{where}.controllers: {exc}") from None
    reflex = None
    if data.get("reflex") is not None:
        r = data["reflex"]
        thresholds = r.get("force_thresholds") if isinstance(r, Mapping) else None
        if not (isinstance(thresholds, list) and len(thresholds) == 6
                and all(isinstance(v, int | float) and v > 0 for v in thresholds)):
            raise ProfileError(f"{where}.reflex.force_thresholds: expected 6 positive numbers "
                               f"[fx fy fz tx ty tz], got {thresholds!r}")
        reflex = ReflexSpec(tuple(float(v) for v in thresholds),
                            _string(r, "recovery_action", f"{where}.reflex"),
                            _string(r, "recovery_type", f"{where}.reflex"),
                            _robot_state(r.get("state"), f"{where}.reflex.state"))
    protective_stop = _protective_stop(data.get("protective_stop"), f"{where}.protective_stop")
    return DriverProfile(
        driver=_string(data, "driver", where),
        publish_rate=_number(data, "publish_rate", where, positive=True),
        joint_states_topic=_string(data, "joint_states_topic", where),
        wrench=wrench,
        tf=tuple(tf),
        controller_manager=_string(data, "controller_manager", where, "controller_manager"),
        controllers=controllers,
        speed_scaling_topic=_string(data, "speed_scaling_topic", where, ""),
        reflex=reflex,
        protective_stop=protective_stop,
        options=resolved,
    )
