"""What `make robot` was given (`RobotSpec`, its command line) and what it measured (`Plan`).

Its own module so that both `generate` (which makes a plan) and `templates` (which write it out) import it.
"""

from __future__ import annotations

import re
from dataclasses import dataclass

import numpy as np
from thesis_demos.geometry import DemoGeometry

from robot_setup.analysis import PoseReport
from robot_setup.driver import DriverInterface

__all__ = ["Plan", "RobotSpec", "command_line", "recorded_command"]


@dataclass(frozen=True)
class RobotSpec:
    """What the user gives: `make robot NAME=... URDF=... TIP=... [BASE=...] [TOOL_MASS=...] [DRIVER=...]`."""

    name: str
    urdf: str  # a path, or a path relative to example-robot-data's robots/
    tip: str  # the flange link the sensor and tool go on
    base: str = ""  # the base frame; empty: the URDF root (or its only fixed child, if the root is a 'world')
    tool_mass: float = 1.0  # [kg]
    driver: str = ""  # a mujoco_driver profile name or YAML path the hardware files are for; empty: generic


def command_line(spec: RobotSpec, with_driver: bool = True) -> str:
    """The `make robot` command of `spec` (what the package records; `recorded_command` reads it back).

    Args:
        spec: The command's arguments.
        with_driver: Include `DRIVER=` (the simulation's files leave it out: they are the same for any
            driver).
    """

    def num(v: float) -> str:
        return f"{v:.10g}"

    return (
        f"make robot NAME={spec.name} URDF={spec.urdf} TIP={spec.tip}"
        + (f" BASE={spec.base}" if spec.base else "")
        + f" TOOL_MASS={num(spec.tool_mass)}"
        + (f" DRIVER={spec.driver}" if with_driver and spec.driver else "")
    )


_COMMAND = re.compile(
    r"`make robot NAME=(\S+) URDF=(\S+) TIP=(\S+)(?: BASE=(\S+))? TOOL_MASS=(\S+?)(?: DRIVER=(\S+))?`"
)


def recorded_command(readme: str) -> RobotSpec | None:
    """The `make robot` command a generated package's README records (None: not generated)."""
    match = _COMMAND.search(readme)
    if not match:
        return None
    name, urdf, tip, base, mass, driver = match.groups()
    return RobotSpec(name, urdf, tip, base or "", float(mass), driver or "")


@dataclass(frozen=True)
class Plan:
    """Everything the package's files say, measured."""

    spec: RobotSpec
    source: str  # make_description's --source
    removed: tuple[str, ...]  # subtrees below the flange (a gripper the tool replaces)
    base: str
    urdf_xml: str
    joints: tuple[str, ...]
    reach: float
    geometry: DemoGeometry
    gap: float
    obstacle_size: tuple[float, float, float]
    obstacle_position: tuple[float, float, float]
    start: PoseReport
    home: np.ndarray
    threshold: float
    hard_stop: float
    kp: tuple[float, ...]
    kv: tuple[float, ...]
    armature: float
    efforts: tuple[float, ...]
    driver: DriverInterface  # the hardware files' driver (generic, or from the DRIVER profile)
