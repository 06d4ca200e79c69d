"""A robot package's named poses (`config/named_poses.yaml`) checked against its URDF.

Pure: standard library, numpy and the parameter declarations (`named_poses.params`). A pose names every
arm joint's angle [rad]; limits are joint-space velocity and acceleration, one number for all joints or one
per joint, capped by the URDF's velocity limits. Continuous joints go to the nearest equivalent angle
(whole turns are not undone).
"""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from compliant_common.errors import StackError

from named_poses.params import FILE_KEYS, NamedPoseSettings

__all__ = ["NamedPoses", "PoseError", "UrdfJoint", "urdf_joints"]


_DEFAULTS = NamedPoseSettings()


class PoseError(StackError):
    """A named pose or limit that cannot be used; the message names the key."""


@dataclass(frozen=True)
class UrdfJoint:
    """One URDF joint: type, position limits [rad], velocity limit [rad/s] (inf: none)."""

    name: str
    continuous: bool
    lower: float
    upper: float
    velocity: float


def urdf_joints(urdf_xml: str) -> dict[str, UrdfJoint]:
    """The movable (revolute, continuous, prismatic) joints of a URDF by name.

    Raises:
        PoseError: The text is not a URDF.
    """
    try:
        robot = ET.fromstring(urdf_xml)
    except ET.ParseError as exc:
        raise PoseError(f"robot_description is not valid XML: {exc}") from exc
    out = {}
    for joint in robot.findall("joint"):
        kind = joint.get("type")
        if kind not in ("revolute", "continuous", "prismatic"):
            continue
        limit = joint.find("limit")
        attrs = limit.attrib if limit is not None else {}

        def get(key: str, default: float, attrs: dict = attrs) -> float:
            return float(attrs.get(key, default))

        continuous = kind == "continuous"
        name = joint.get("name", "")  # required by the URDF format
        out[name] = UrdfJoint(
            name=name,
            continuous=continuous,
            lower=-math.inf if continuous else get("lower", 0.0),
            upper=math.inf if continuous else get("upper", 0.0),
            velocity=get("velocity", math.inf) or math.inf,
        )
    return out


def _per_joint(value: Any, key: str, joints: Sequence[str]) -> np.ndarray:
    if isinstance(value, Mapping):
        missing = [j for j in joints if j not in value]
        if missing:
            raise PoseError(f"{key}: no value for joints {missing}")
        values = [value[j] for j in joints]
    else:
        values = [value] * len(joints)
    try:
        arr = np.array([float(v) for v in values])
    except (TypeError, ValueError) as exc:
        raise PoseError(f"{key}: expected numbers, got {value!r}") from exc
    if not np.all(np.isfinite(arr)) or np.any(arr <= 0):
        raise PoseError(f"{key}: must be positive numbers, got {value!r}")
    return arr


@dataclass(frozen=True)
class NamedPoses:
    """Named joint configurations and joint-space limits for moves to them.

    Attributes:
        joints: The arm's joints the poses name, in the order of `poses` values.
        poses: Name -> angles [rad] (joint order).
        max_velocity: Per joint [rad/s] (after the URDF cap).
        max_acceleration: Per joint [rad/s^2].
        continuous: Per joint, True for a continuous joint.
    """

    joints: tuple[str, ...]
    poses: dict[str, np.ndarray]
    max_velocity: np.ndarray
    max_acceleration: np.ndarray
    continuous: tuple[bool, ...]
    lower: tuple[float, ...] = ()  # per joint [rad] (the URDF's; () unchecked)
    upper: tuple[float, ...] = ()

    @classmethod
    def from_dict(cls, data: Mapping[str, Any], urdf: Mapping[str, UrdfJoint]) -> NamedPoses:
        """Validate named_poses.yaml's mapping against the URDF's joints.

        Raises:
            PoseError: Unknown key, no poses, a pose missing or adding a joint, an angle outside the
                joint's limits, bad limits.
        """
        if not isinstance(data, Mapping):
            raise PoseError(f"named poses must be a mapping, got {type(data).__name__}")
        unknown = set(data) - set(FILE_KEYS)
        if unknown:
            raise PoseError(f"unknown keys {sorted(unknown)}; known: {', '.join(FILE_KEYS)}")
        poses = data.get("poses")
        if not isinstance(poses, Mapping) or not poses:
            raise PoseError("poses: expected a mapping name -> {joint: angle [rad]} with at least one pose")
        first = next(iter(poses.values()))
        if not isinstance(first, Mapping):
            raise PoseError(f"poses/{next(iter(poses))}: expected a mapping joint -> angle [rad]")
        joints = tuple(first)
        arrays = {}
        for name, pose in poses.items():
            if not isinstance(pose, Mapping) or set(pose) != set(joints):
                raise PoseError(f"poses/{name}: must name the same joints as the first pose {list(joints)}")
            values = []
            for joint in joints:
                if joint not in urdf:
                    raise PoseError(f"poses/{name}/{joint}: not a movable joint of the URDF {sorted(urdf)}")
                try:
                    angle = float(pose[joint])
                except (TypeError, ValueError) as exc:
                    raise PoseError(
                        f"poses/{name}/{joint}: expected an angle [rad], got {pose[joint]!r}"
                    ) from exc
                info = urdf[joint]
                if not (info.lower <= angle <= info.upper):
                    raise PoseError(
                        f"poses/{name}/{joint}: {angle} rad is outside the joint's limits "
                        f"[{info.lower}, {info.upper}]"
                    )
                values.append(angle)
            arrays[str(name)] = np.array(values)
        velocity = _per_joint(data.get("max_velocity", _DEFAULTS.max_velocity), "max_velocity", joints)
        velocity = np.minimum(velocity, [urdf[j].velocity for j in joints])
        acceleration = _per_joint(
            data.get("max_acceleration", _DEFAULTS.max_acceleration), "max_acceleration", joints
        )
        return cls(joints, arrays, velocity, acceleration, tuple(urdf[j].continuous for j in joints),
                   tuple(urdf[j].lower for j in joints), tuple(urdf[j].upper for j in joints))

    def goal_of(
        self, names: Sequence[str], positions: Sequence[float], label: str = "the goal"
    ) -> np.ndarray:
        """The angles [rad] of `self.joints` taken from `names`/`positions` (other joints ignored).

        Raises:
            PoseError: Lengths differ, a joint is missing, a value is not finite or outside its limits.
        """
        if len(names) != len(positions):
            raise PoseError(f"{label}: {len(names)} joint names but {len(positions)} positions")
        given = dict(zip(names, positions, strict=True))
        missing = [j for j in self.joints if j not in given]
        if missing:
            raise PoseError(f"{label}: no position for {missing} (the arm's joints are {list(self.joints)})")
        goal = np.array([float(given[j]) for j in self.joints])
        for i, joint in enumerate(self.joints):
            lo, hi = (self.lower[i], self.upper[i]) if self.lower else (-math.inf, math.inf)
            if not (math.isfinite(goal[i]) and lo <= goal[i] <= hi):
                raise PoseError(f"{label}: {joint} {goal[i]} rad is outside the joint's limits [{lo}, {hi}]")
        return goal

    def goal(self, name: str, current: Sequence[float] | np.ndarray) -> np.ndarray:
        """The pose's angles [rad], continuous joints moved to the equivalent nearest `current`.

        Raises:
            PoseError: Unknown name (the known ones are listed).
        """
        if name not in self.poses:
            raise PoseError(f"no named pose {name!r}; known: {sorted(self.poses)}")
        goal = self.poses[name].copy()
        for i, continuous in enumerate(self.continuous):
            if continuous:
                goal[i] += 2.0 * math.pi * round((current[i] - goal[i]) / (2.0 * math.pi))
        return goal
