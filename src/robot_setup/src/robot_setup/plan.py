"""What `make robot` was given (`RobotSpec`, its command line) and what it measured (`Plan`).

Its own module so that both `generate` (which makes a plan) and `templates` (which write it out) import it.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass

import numpy as np
from compliant_common.errors import StackError
from thesis_demos.geometry import DemoGeometry

from robot_setup.analysis import PoseReport
from robot_setup.driver import DriverInterface

__all__ = [
    "GeneratorError", "Plan", "RobotSpec", "command_line", "parse_held", "parse_rpy", "recorded_command",
]


class GeneratorError(StackError):
    """Bad input (unknown link, missing URDF, bad name or mass), or no usable start pose; named."""


@dataclass(frozen=True)
class RobotSpec:
    """What the user gives: `make robot NAME=... URDF=... TIP=... [BASE=...] [TOOL_MASS=...] [TOOL_RPY=...]
    [HELD=...] [DRIVER=...]`."""

    name: str
    urdf: str  # a path, or a path relative to example-robot-data's robots/
    tip: str  # the flange link the sensor and tool go on
    base: str = ""  # the base frame; empty: the URDF root (or its only fixed child, if the root is a 'world')
    tool_mass: float = 1.0  # [kg]
    driver: str = ""  # a mujoco_driver profile name or YAML path the hardware files are for; empty: generic
    # The sensor's (and tool's) mounting on the flange, roll pitch yaw [rad]; None: straight, or an adapter
    # angle the generator picks when the straight mounting cannot point the tool down.
    tool_rpy: tuple[float, float, float] | None = None
    held: tuple[tuple[str, float], ...] = ()  # positions of joints outside BASE..TIP (others: 0 in limits)


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
        + (f" TOOL_RPY={','.join(num(v) for v in spec.tool_rpy)}" if spec.tool_rpy is not None else "")
        + (f" HELD={','.join(f'{j}={num(v)}' for j, v in spec.held)}" if spec.held else "")
        + (f" DRIVER={spec.driver}" if with_driver and spec.driver else "")
    )


_COMMAND = re.compile(
    r"`make robot NAME=(\S+) URDF=(\S+) TIP=(\S+)(?: BASE=(\S+))? TOOL_MASS=(\S+?)(?: TOOL_RPY=(\S+?))?"
    r"(?: HELD=(\S+?))?(?: DRIVER=(\S+))?`"
)


def parse_rpy(text: str) -> tuple[float, float, float]:
    """TOOL_RPY's "roll,pitch,yaw" [rad] (commas or spaces).

    Raises:
        ValueError: Not three finite numbers.
    """
    words = text.replace(",", " ").split()
    values = tuple(float(w) for w in words)
    if len(values) != 3 or not all(math.isfinite(v) for v in values):
        raise ValueError(f"TOOL_RPY={text!r}: give three angles roll,pitch,yaw [rad]")
    return values[0], values[1], values[2]


def parse_held(text: str) -> tuple[tuple[str, float], ...]:
    """HELD's "joint=position,joint=position" [rad or m].

    Raises:
        ValueError: An entry that is not joint=number.
    """
    held = []
    for entry in text.replace(",", " ").split():
        name, sep, value = entry.partition("=")
        try:
            number = float(value)
        except ValueError:
            number = math.nan
        if not sep or not name or not math.isfinite(number):
            raise ValueError(f"HELD={text!r}: give joint=position entries, e.g. HELD=gripper=0.02,head=0")
        held.append((name, number))
    return tuple(held)


def recorded_command(readme: str) -> RobotSpec | None:
    """The `make robot` command a generated package's README records (None: not generated)."""
    match = _COMMAND.search(readme)
    if not match:
        return None
    name, urdf, tip, base, mass, rpy, held, driver = match.groups()
    return RobotSpec(name, urdf, tip, base or "", float(mass), driver or "",
                     parse_rpy(rpy) if rpy else None, parse_held(held) if held else ())


@dataclass(frozen=True)
class Plan:
    """Everything the package's files say, measured."""

    spec: RobotSpec
    source: str  # make_description's --source
    removed: tuple[str, ...]  # subtrees below the flange (a gripper the tool replaces)
    base: str
    tool_rpy: tuple[float, float, float]  # the sensor's mounting on the flange (TOOL_RPY, or the adapter)
    adapter: str  # why that mounting ("" when straight as given)
    held: tuple[tuple[str, float], ...]  # joints outside BASE..TIP and where they are held
    urdf_xml: str
    joints: tuple[str, ...]
    reach: float
    geometry: DemoGeometry
    gap: float
    obstacle_size: tuple[float, float, float]
    obstacle_position: tuple[float, float, float]
    start: PoseReport
    tip_in_base: tuple[float, float, float]  # the start pose's tool tip in `base` (start.tip: URDF root)
    home: np.ndarray
    threshold: float
    hard_stop: float
    servo_joints: tuple[str, ...]  # the arm's joints, then the held ones: kp, kv, efforts in this order
    kp: tuple[float, ...]
    kv: tuple[float, ...]
    armature: float
    efforts: tuple[float, ...]
    driver: DriverInterface  # the hardware files' driver (generic, or from the DRIVER profile)
    acceleration: float  # [rad/s^2] jog_arm's joint acceleration limit (default_max_acceleration)
    servo_note: str = ""  # why kp and kv are below the effort rule's ("": they are not)
    linear: tuple[str, ...] = ()  # the servo joints that are prismatic (a rail): gains in N/m
