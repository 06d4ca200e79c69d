"""Scene settings: the robot-specific numbers of the simulation, read once and validated.

The YAML file (a robot package's ``config/sim.yaml``) is the only robot-specific input besides the URDF.
All lengths in metres, angles in radians, masses in kilograms, expressed in the robot's base frame
(the URDF root link), which is also the MuJoCo world frame: the table top is its z = 0 plane.

Per-joint values (start pose, gains, armature) are given as a mapping ``joint name -> value``, a list in
URDF joint order, or one number for all joints; they are resolved against the URDF's joints when the
scene is built (:meth:`PerJoint.resolve`).
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import yaml
from compliant_common.errors import StackError

__all__ = [
    "Box",
    "ConfigError",
    "LinkNames",
    "NoiseConfig",
    "PerJoint",
    "SceneConfig",
    "ServoConfig",
    "Surface",
    "TableConfig",
    "load_scene_config",
]

# Only integrators that treat the servos' velocity gain implicitly: with explicit Euler the stiff servos
# of light wrist joints go unstable at a 2 ms step.
INTEGRATORS = ("implicitfast", "implicit")


class ConfigError(StackError):
    """Raised for a missing, unknown or out-of-range scene setting; the message names the key."""


def _number(
    value: Any, key: str, low: float = -math.inf, high: float = math.inf, strict_low: bool = False
) -> float:
    if isinstance(value, bool) or not isinstance(value, int | float):
        raise ConfigError(f"{key}: expected a number, got {value!r}")
    value = float(value)
    if not math.isfinite(value) or value < low or value > high or (strict_low and value <= low):
        bound = f"> {low}" if strict_low else f">= {low}"
        raise ConfigError(f"{key}: {value} out of range ({bound}, <= {high})")
    return value


def _vector(value: Any, key: str, size: int, positive: bool = False) -> tuple[float, ...]:
    if not isinstance(value, Sequence) or isinstance(value, str) or len(value) != size:
        raise ConfigError(f"{key}: expected a list of {size} numbers, got {value!r}")
    return tuple(_number(v, f"{key}[{i}]", 0.0 if positive else -math.inf, strict_low=positive)
                 for i, v in enumerate(value))


def _section(
    data: Mapping[str, Any], key: str, known: Sequence[str], required: bool = True
) -> dict[str, Any]:
    value = data.get(key)
    if value is None:
        if required:
            raise ConfigError(f"{key}: missing section")
        return {}
    if not isinstance(value, Mapping):
        raise ConfigError(f"{key}: expected a mapping, got {value!r}")
    unknown = set(value) - set(known)
    if unknown:
        raise ConfigError(f"{key}: unknown keys {sorted(unknown)}; known: {sorted(known)}")
    return dict(value)


@dataclass(frozen=True)
class PerJoint:
    """A per-joint value: one number, a list in joint order, or a mapping joint name -> number."""

    key: str
    value: float | tuple[float, ...] | dict[str, float]
    low: float = -math.inf
    strict_low: bool = False

    @classmethod
    def parse(cls, value: Any, key: str, low: float = -math.inf, strict_low: bool = False) -> PerJoint:
        """Check the numbers (names are checked later, against the URDF)."""
        if isinstance(value, Mapping):
            parsed: Any = {
                str(k): _number(v, f"{key}.{k}", low, strict_low=strict_low) for k, v in value.items()
            }
        elif isinstance(value, Sequence) and not isinstance(value, str):
            parsed = tuple(_number(v, f"{key}[{i}]", low, strict_low=strict_low) for i, v in enumerate(value))
        else:
            parsed = _number(value, key, low, strict_low=strict_low)
        return cls(key, parsed, low, strict_low)

    def resolve(self, joint_names: Sequence[str]) -> list[float]:
        """Values in ``joint_names`` order.

        Raises:
            ConfigError: On a wrong list length, or names missing from / unknown to the URDF.
        """
        if isinstance(self.value, float):
            return [self.value] * len(joint_names)
        if isinstance(self.value, tuple):
            if len(self.value) != len(joint_names):
                raise ConfigError(
                    f"{self.key}: {len(self.value)} values for {len(joint_names)} joints {list(joint_names)}"
                )
            return list(self.value)
        missing = [n for n in joint_names if n not in self.value]
        unknown = [n for n in self.value if n not in joint_names]
        if missing or unknown:
            raise ConfigError(
                f"{self.key}: joints missing {missing}, unknown {unknown}; URDF joints {list(joint_names)}"
            )
        return [self.value[n] for n in joint_names]


@dataclass(frozen=True)
class LinkNames:
    """URDF links the simulation needs (created by ``make_description``)."""

    ft_sensor: str = "ft_sensor"
    tool: str = "tool"
    eef: str = "tool_tip"


@dataclass(frozen=True)
class TableConfig:
    """The table the robot stands on; its top is the base frame's z = 0 plane."""

    size: tuple[float, float] = (1.2, 0.8)  # top extents x, y [m]
    thickness: float = 0.05  # [m]
    height: float = 0.75  # top above the floor [m]
    center: tuple[float, float] = (0.3, 0.0)  # top centre in the base frame [m]


@dataclass(frozen=True)
class Box:
    """A fixed box obstacle: centre position [m], orientation rpy [rad], full extents [m]."""

    position: tuple[float, float, float]
    size: tuple[float, float, float]
    rpy: tuple[float, float, float] = (0.0, 0.0, 0.0)


@dataclass(frozen=True)
class Hole:
    """A plate with a square, chamfered hole lying on the obstacle block (mujoco_driver.fixtures): the peg's
    width, the clearance, depth and chamfer [m], the plate's side [m], the hole's offset from the block's
    centre (dx, dy [m], yaw [rad]) and its tilt about its own x then y axis through the top's centre (roll,
    pitch [rad]: its axis no longer along the block's normal), which a task is not told."""

    peg: float = 0.01
    clearance: float = 0.0004
    depth: float = 0.02
    chamfer: float = 0.001
    plate: float = 0.12
    offset: tuple[float, float, float] = (0.0, 0.0, 0.0)
    tilt: tuple[float, float] = (0.0, 0.0)


@dataclass(frozen=True)
class Hand:
    """A person's hand lying on the obstacle block (README, Fixtures): a box of ISO/TS 15066's hand mass on a
    vertical slide joint whose spring is the hand's tissue (Annex A: 0.6 kg, 75 N/mm), backed by the block:
    pressed more than `travel` it is on the bone (the joint's limit). `free`: the hand held in the air `at`
    a point instead, ISO/TS 15066's transient contact: the 0.6 kg moves away when struck, the tissue is the
    contact's stiffness (75 N/mm against a tool much heavier than the hand) and a weak spring is the arm
    that holds it."""

    mass: float = 0.6  # [kg] ISO/TS 15066 Table A.3
    stiffness: float = 75e3  # [N/m] ISO/TS 15066 Table A.3 (75 N/mm)
    size: tuple[float, float, float] = (0.09, 0.09, 0.03)  # [m] a palm (a guess at a hand's size)
    travel: float = 0.015  # [m] tissue compression before bone (a guess: 1125 N at 75 N/mm)
    damping_ratio: float = 0.2  # of the spring-mass (a guess: tissue is well damped)
    free: bool = False  # fixture free_hand: held in the air, nothing under it (a strike)
    at: tuple[float, float, float] = (0.0, 0.0, 0.0)  # [m] free hand: the centre of its underside
    hold_stiffness: float = 1e3  # [N/m] free hand: the arm holding it up, critically damped (a guess)
    reach: float = 0.1  # [m] free hand: how far a strike may push it down (its slide's range)


@dataclass(frozen=True)
class Surface:
    """The part a finishing task works on (README, Fixtures): `plane` is the obstacle block itself (tilted by
    the driver's `surface_tilt`); `cylinder` (axis along the base's y) and `sphere` replace the block, their
    top at its top centre moved by `offset` (dx, dy, dz [m]), which a task is not told. Its sliding friction
    with the tool is `friction` (it outranks the tool's: MuJoCo geom priority)."""

    kind: str = "plane"
    radius: float = 0.0  # [m] cylinder and sphere
    offset: tuple[float, float, float] = (0.0, 0.0, 0.0)
    friction: float = 0.3  # a guess: a polishing pad on metal


@dataclass(frozen=True)
class ServoConfig:
    """Joint position servos (PD with velocity feed-forward, like an industrial joint controller).

    Attributes:
        kp: Position gain [Nm/rad].
        kv: Velocity gain [Nm s/rad].
        armature: Reflected rotor inertia added to each joint [kg m^2] (real geared drives have it; it also
            keeps stiff servos stable at the timestep).
        max_acceleration: Setpoint acceleration limit in every command mode [rad/s^2 or m/s^2].
        max_deceleration: The limit while a joint slows down in velocity and trajectory modes, as a
            robot controller's stop (None: max_acceleration).
        payload_feedforward: Add the torque that holds the tool's weight (like a robot controller's payload
            setting), so the arm does not sag under it; the sensor still measures the weight.
    """

    kp: PerJoint
    kv: PerJoint
    armature: PerJoint
    max_acceleration: PerJoint
    payload_feedforward: bool = True
    max_deceleration: PerJoint | None = None


@dataclass(frozen=True)
class NoiseConfig:
    """Gaussian noise added to the wrench reading (standard deviations; 0 disables)."""

    force_std: float = 0.0  # [N]
    torque_std: float = 0.0  # [Nm]
    seed: int | None = None


@dataclass(frozen=True)
class SceneConfig:
    """Everything robot-specific about the simulated scene except the URDF.

    ``held_joints`` (joint name -> position; in YAML a list of ``<joint>: position``, as jog_arm's) are the
    joints outside the arm's chain (a gripper, a head,
    another arm): their servos hold them there, velocity commands leave them out, ``start_pose`` does not
    list them. Every other movable joint is an arm joint.
    """

    start_pose: PerJoint
    servo: ServoConfig
    timestep: float = 0.002  # [s]
    integrator: str = "implicitfast"
    links: LinkNames = field(default_factory=LinkNames)
    table: TableConfig = field(default_factory=TableConfig)
    obstacle: Box | None = None
    wrench_noise: NoiseConfig = field(default_factory=NoiseConfig)
    held_joints: Mapping[str, float] = field(default_factory=dict)
    hole: Hole | None = None
    hand: Hand | None = None
    surface: Surface | None = None

    @classmethod
    def from_dict(cls, data: Mapping[str, Any]) -> SceneConfig:
        """Validate a parsed YAML mapping.

        Raises:
            ConfigError: Naming the first bad key.
        """
        if not isinstance(data, Mapping):
            raise ConfigError(f"scene config must be a mapping, got {type(data).__name__}")
        known = (
            "timestep", "integrator", "links", "table", "obstacle", "start_pose", "servo", "wrench_noise",
            "held_joints",
        )
        unknown = set(data) - set(known)
        if unknown:
            raise ConfigError(f"unknown top-level keys {sorted(unknown)}; known: {list(known)}")
        timestep = _number(data.get("timestep", 0.002), "timestep", 0.0, 0.01, strict_low=True)
        integrator = data.get("integrator", "implicitfast")
        if integrator not in INTEGRATORS:
            raise ConfigError(f"integrator: {integrator!r} not one of {INTEGRATORS}")
        links = _section(data, "links", ("ft_sensor", "tool", "eef"), required=False)
        for key, value in links.items():
            if not isinstance(value, str) or not value:
                raise ConfigError(f"links.{key}: expected a link name, got {value!r}")
        table = _section(data, "table", ("size", "thickness", "height", "center"), required=False)
        table_cfg = TableConfig(
            size=_vector(table.get("size", TableConfig.size), "table.size", 2, positive=True),  # type: ignore[arg-type]
            thickness=_number(
                table.get("thickness", TableConfig.thickness), "table.thickness", 0.0, strict_low=True
            ),
            height=_number(table.get("height", TableConfig.height), "table.height", 0.0),
            center=_vector(table.get("center", TableConfig.center), "table.center", 2),  # type: ignore[arg-type]
        )
        obstacle = None
        if data.get("obstacle") is not None:
            obs = _section(data, "obstacle", ("position", "size", "rpy"))
            if "position" not in obs or "size" not in obs:
                raise ConfigError("obstacle: needs position and size")
            obstacle = Box(
                position=_vector(obs["position"], "obstacle.position", 3),  # type: ignore[arg-type]
                size=_vector(obs["size"], "obstacle.size", 3, positive=True),  # type: ignore[arg-type]
                rpy=_vector(obs.get("rpy", (0.0, 0.0, 0.0)), "obstacle.rpy", 3),  # type: ignore[arg-type]
            )
        if "start_pose" not in data:
            raise ConfigError("start_pose: missing (joint name -> angle [rad])")
        servo = _section(data, "servo", ("kp", "kv", "armature", "max_acceleration", "max_deceleration",
                                           "payload_feedforward"))
        for key in ("kp", "kv"):
            if key not in servo:
                raise ConfigError(f"servo.{key}: missing")
        feedforward = servo.get("payload_feedforward", True)
        if not isinstance(feedforward, bool):
            raise ConfigError(f"servo.payload_feedforward: expected true/false, got {feedforward!r}")
        noise = _section(data, "wrench_noise", ("force_std", "torque_std", "seed"), required=False)
        seed = noise.get("seed")
        if seed is not None and (isinstance(seed, bool) or not isinstance(seed, int)):
            raise ConfigError(f"wrench_noise.seed: expected an integer, got {seed!r}")
        held = data.get("held_joints") or []
        entries = [held] if isinstance(held, Mapping) else held
        if not isinstance(entries, list) or not all(isinstance(e, Mapping) for e in entries):
            raise ConfigError(f"held_joints: expected a list of <joint>: position entries, got {held!r}")
        return cls(
            held_joints={str(k): _number(v, f"held_joints.{k}") for e in entries for k, v in e.items()},
            start_pose=PerJoint.parse(data["start_pose"], "start_pose"),
            servo=ServoConfig(
                kp=PerJoint.parse(servo["kp"], "servo.kp", 0.0, strict_low=True),
                kv=PerJoint.parse(servo["kv"], "servo.kv", 0.0),
                armature=PerJoint.parse(servo.get("armature", 0.0), "servo.armature", 0.0),
                max_acceleration=PerJoint.parse(servo.get("max_acceleration", 10.0), "servo.max_acceleration",
                                                0.0, strict_low=True),
                payload_feedforward=feedforward,
                max_deceleration=None if servo.get("max_deceleration") is None else PerJoint.parse(
                    servo["max_deceleration"], "servo.max_deceleration", 0.0, strict_low=True),
            ),
            timestep=timestep,
            integrator=integrator,
            links=LinkNames(**links),
            table=table_cfg,
            obstacle=obstacle,
            wrench_noise=NoiseConfig(
                force_std=_number(noise.get("force_std", 0.0), "wrench_noise.force_std", 0.0),
                torque_std=_number(noise.get("torque_std", 0.0), "wrench_noise.torque_std", 0.0),
                seed=seed,
            ),
        )


def load_scene_config(path: str) -> SceneConfig:
    """Read and validate a scene YAML file.

    Raises:
        ConfigError: If the file cannot be read or parsed, or a setting is invalid.
    """
    try:
        with open(path, encoding="utf-8") as handle:
            data = yaml.safe_load(handle)
    except (OSError, yaml.YAMLError) as exc:
        raise ConfigError(f"cannot read scene config {path}: {exc}") from exc
    return SceneConfig.from_dict(data or {})
