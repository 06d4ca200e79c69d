"""A taught program: waypoints of a hand-guided motion, as a readable YAML file (no ROS here).

A program holds what was recorded, simplified to waypoints (`simplify`): per waypoint the time since the start
[s], the joint positions, the tool pose in the base frame (position [m], quaternion x, y, z, w) and the wrench
[N, Nm], and whether it is a keyframe. `robot` names the arm it was recorded on (its URDF's robot name and its
joints): a program of another arm is refused with the reason (`check_robot`). See teach's README.
"""

from __future__ import annotations

import datetime
import itertools
import math
import os
import re
from collections.abc import Sequence
from dataclasses import dataclass, field

import yaml
from compliant_common.errors import StackError

__all__ = ["FORMAT", "Program", "ProgramError", "ProgramStore", "Waypoint", "check_name"]

FORMAT = 1  # the file format's version
_NAME = re.compile(r"^[A-Za-z0-9][A-Za-z0-9_.-]{0,63}$")


class ProgramError(StackError):
    """A program name, file or content is not valid; the message says what to change."""


def check_name(name: str) -> str:
    """`name` if it can name a program file (letters, digits, '_', '-', '.'; 1-64 characters).

    Raises:
        ProgramError: It cannot.
    """
    if not isinstance(name, str) or not _NAME.match(name):
        raise ProgramError(f"program name {name!r}: use 1-64 letters, digits, '_', '-' or '.', starting "
                           "with a letter or digit")
    return name


@dataclass(frozen=True)
class Waypoint:
    """One waypoint: time since the start [s], joints [rad or m], position [m], orientation (x, y, z, w),
    wrench (fx, fy, fz, tx, ty, tz) [N, Nm], keyframe (marked by a call or a key while recording)."""

    t: float
    joints: tuple[float, ...]
    position: tuple[float, ...]
    orientation: tuple[float, ...]
    wrench: tuple[float, ...] = (0.0,) * 6
    keyframe: bool = False


@dataclass(frozen=True)
class Program:
    """A recorded motion; see the module docstring."""

    name: str
    robot: str
    joint_names: tuple[str, ...]
    base_frame: str
    tip_frame: str
    waypoints: tuple[Waypoint, ...]
    rate: float = 50.0  # [Hz] the recording rate
    position_tolerance: float = 0.001  # [m] of the simplification
    angle_tolerance: float = math.radians(1.0)  # [rad]
    samples: int = 0  # recorded before simplification
    recorded: str = ""  # ISO 8601 UTC
    bag: str = ""  # the raw stream's rosbag, if kept
    notes: dict[str, str] = field(default_factory=dict)

    @property
    def duration(self) -> float:
        return self.waypoints[-1].t if self.waypoints else 0.0

    @property
    def length(self) -> float:
        """Path length of the tool position [m]."""
        return sum(math.dist(a.position, b.position) for a, b in itertools.pairwise(self.waypoints))

    def check_robot(self, robot: str, joint_names: Sequence[str]) -> None:
        """Raises ProgramError unless the program was recorded on this robot with these joints."""
        if robot != self.robot:
            raise ProgramError(f"program '{self.name}' was recorded on robot '{self.robot}', this is "
                               f"'{robot}'")
        if tuple(joint_names) != self.joint_names:
            raise ProgramError(f"program '{self.name}' has joints {list(self.joint_names)}, this robot "
                               f"{list(joint_names)}")

    def summary(self) -> str:
        keys = sum(w.keyframe for w in self.waypoints)
        return (f"{self.name}: robot {self.robot}, {len(self.waypoints)} waypoints ({keys} keyframes) from "
                f"{self.samples} samples, {self.duration:.2f} s, {self.length * 1e3:.0f} mm")

    # --- YAML ---
    def to_dict(self) -> dict[str, object]:
        return {
            "format": FORMAT,
            "name": self.name,
            "robot": self.robot,
            "recorded": self.recorded,
            "base_frame": self.base_frame,
            "tip_frame": self.tip_frame,
            "joint_names": list(self.joint_names),
            "rate": self.rate,
            "position_tolerance": self.position_tolerance,
            "angle_tolerance": self.angle_tolerance,
            "samples": self.samples,
            "bag": self.bag,
            "notes": dict(self.notes),
            "waypoints": [
                {"t": _r(w.t, 4), "joints": [_r(q, 6) for q in w.joints],
                 "position": [_r(p, 6) for p in w.position], "orientation": [_r(q, 7) for q in w.orientation],
                 "wrench": [_r(f, 3) for f in w.wrench], "keyframe": w.keyframe}
                for w in self.waypoints
            ],
        }

    def to_yaml(self) -> str:
        head = (f"# Program '{self.name}' taught by hand on {self.robot} (teach package). Times [s], joints "
                "[rad],\n# position [m] and orientation (x, y, z, w) of tip_frame in base_frame, wrench "
                "[N, Nm].\n")
        return head + yaml.safe_dump(self.to_dict(), sort_keys=False, default_flow_style=None, width=110)

    @classmethod
    def from_dict(cls, data: object, source: str = "program") -> Program:
        """A program from its YAML mapping.

        Raises:
            ProgramError: A missing or malformed field, named.
        """
        if not isinstance(data, dict):
            raise ProgramError(f"{source}: expected a mapping of program fields")
        if data.get("format") != FORMAT:
            raise ProgramError(f"{source}: format {data.get('format')!r}, this version reads {FORMAT}")
        try:
            joints = tuple(str(n) for n in data["joint_names"])
            points: list[Waypoint] = []
            for i, w in enumerate(data["waypoints"]):
                point = Waypoint(float(w["t"]), tuple(float(q) for q in w["joints"]),
                                 _vec(w["position"], 3), _vec(w["orientation"], 4),
                                 _vec(w.get("wrench", [0.0] * 6), 6), bool(w.get("keyframe", False)))
                if len(point.joints) != len(joints):
                    raise ProgramError(f"{source}: waypoint {i} has {len(point.joints)} joints, joint_names "
                                       f"{len(joints)}")
                if points and point.t < points[-1].t:
                    raise ProgramError(f"{source}: waypoint {i} goes back in time ({point.t} s)")
                points.append(point)
            if not points:
                raise ProgramError(f"{source}: no waypoints")
            return cls(
                name=check_name(str(data["name"])), robot=str(data["robot"]), joint_names=joints,
                base_frame=str(data["base_frame"]), tip_frame=str(data["tip_frame"]), waypoints=tuple(points),
                rate=float(data.get("rate", 50.0)),
                position_tolerance=float(data.get("position_tolerance", 0.001)),
                angle_tolerance=float(data.get("angle_tolerance", math.radians(1.0))),
                samples=int(data.get("samples", len(points))), recorded=str(data.get("recorded", "")),
                bag=str(data.get("bag", "")),
                notes={str(k): str(v) for k, v in (data.get("notes") or {}).items()},
            )
        except (KeyError, TypeError, ValueError) as err:
            raise ProgramError(f"{source}: missing or malformed field: {err}") from None


def _r(x: float, digits: int) -> float:
    return round(float(x), digits)


def _vec(values: object, n: int) -> tuple[float, ...]:
    out = tuple(float(v) for v in values)  # type: ignore[attr-defined]
    if len(out) != n or not all(math.isfinite(v) for v in out):
        raise ValueError(f"expected {n} finite numbers, got {values!r}")
    return out


def now_iso() -> str:
    return datetime.datetime.now(datetime.UTC).strftime("%Y-%m-%dT%H:%M:%SZ")


class ProgramStore:
    """Programs as `<folder>/<name>.yaml` (created on the first save)."""

    def __init__(self, folder: str) -> None:
        self.folder = os.path.expanduser(folder)

    def path(self, name: str) -> str:
        return os.path.join(self.folder, check_name(name) + ".yaml")

    def names(self) -> list[str]:
        if not os.path.isdir(self.folder):
            return []
        return sorted(f[:-5] for f in os.listdir(self.folder) if f.endswith(".yaml") and _NAME.match(f[:-5]))

    def save(self, program: Program, overwrite: bool = False) -> str:
        path = self.path(program.name)
        if os.path.exists(path) and not overwrite:
            raise ProgramError(f"program '{program.name}' exists ({path}): delete it first or choose another "
                               "name")
        os.makedirs(self.folder, exist_ok=True)
        tmp = path + ".tmp"
        with open(tmp, "w", encoding="utf-8") as out:
            out.write(program.to_yaml())
        os.replace(tmp, path)  # a reader never sees half a file
        return path

    def load(self, name: str) -> Program:
        path = self.path(name)
        try:
            with open(path, encoding="utf-8") as src:
                data = yaml.safe_load(src)
        except FileNotFoundError:
            known = ", ".join(self.names()) or "none"
            raise ProgramError(f"no program '{name}' in {self.folder} (programs: {known})") from None
        except yaml.YAMLError as err:
            raise ProgramError(f"{path}: not YAML: {err}") from None
        return Program.from_dict(data, path)

    def delete(self, name: str) -> str:
        path = self.path(name)
        if not os.path.exists(path):
            raise ProgramError(f"no program '{name}' in {self.folder}")
        os.remove(path)
        return path
