"""Test robots and a perfect simulated arm for the jog_arm tests (robot numbers live here, not in src)."""

from __future__ import annotations

import pathlib
import sys
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from jog_arm import JogCalcs, JogSettings

ROBOTS_DIR = (
    pathlib.Path(sys.prefix) / "lib/python3.11/site-packages/cmeel.prefix/share/example-robot-data/robots"
)


@dataclass(frozen=True)
class Robot:
    """A test robot: its URDF and poses chosen for each test (UR5: 6 joints, Panda: 7)."""

    name: str
    urdf_path: pathlib.Path
    tip: str
    planning_frame: str
    start: tuple[float, ...]  # away from singularities and limits (condition number ~5.4)
    near_singular: tuple[float, ...]  # condition number between the thresholds
    singular_joint: int  # moving this joint from near_singular toward `singular_value` nears a singularity
    singular_value: float
    params: dict[str, Any] = field(default_factory=dict)

    @property
    def urdf(self) -> str:
        return self.urdf_path.read_text()


UR5 = Robot(
    "ur5",
    ROBOTS_DIR / "ur_description/urdf/ur5_robot.urdf",
    "tool0",
    "base_link",
    (0.0, -1.2, 1.5, -1.9, -1.57, 0.3),
    (0.0, -1.2, 1.5, -1.9, -0.75, 0.3),  # wrist_2 -> 0 aligns wrist_1 and wrist_3 (wrist singularity)
    4,
    0.0,
)
PANDA = Robot(
    "panda",
    ROBOTS_DIR / "panda_description/urdf/panda.urdf",
    "panda_hand",
    "panda_link0",
    (0.0, -0.5, 0.0, -2.0, 0.0, 1.6, 0.8),
    (0.0, -0.5, 0.0, -1.4, 0.0, 1.6, 0.8),  # joint 4 -> -0.57 puts the wrist on the shoulder axis
    3,
    -0.57,
    # Datasheet acceleration limits [rad/s²] (URDFs carry none).
    {
        "joint_limits": {
            f"panda_joint{i}": {"max_acceleration": a}
            for i, a in enumerate([15.0, 7.5, 10.0, 12.5, 15.0, 20.0, 20.0], 1)
        }
    },
)

# 5 joints; its tip link `gripper` shares its name with the jaw's joint (held at 0). The default length
# scale (0.4 m, twice its reach) puts every posture past 8 (generated packages measure their thresholds).
SO100 = Robot(
    "so100",
    ROBOTS_DIR / "so_arm_description/urdf/so100.urdf",
    "gripper",
    "base",
    (-0.87, 0.59, -0.79, 0.6, -1.5),  # 0.4 rad or more inside the limits
    (-0.87, 0.59, -0.79, 0.6, -1.5),
    0,
    0.0,
    {"singularity_length_scale": 0.2},
)


def make_jog(robot: Robot, **params: Any) -> JogCalcs:
    """A JogCalcs for `robot` with speed-unit commands at 100 Hz unless `params` says otherwise."""
    merged: dict[str, Any] = {
        "ee_frame_name": robot.tip,
        "planning_frame": robot.planning_frame,
        "command_in_type": "speed_units",
        "pub_period": 0.01,
        "incoming_cmd_timeout": 0.5,
        **robot.params,
        **params,
    }
    return JogCalcs(JogSettings.from_params(merged), robot.urdf)


@dataclass
class Trace:
    """What a perfect arm (that reaches every commanded position) did, one row per cycle."""

    positions: list[np.ndarray] = field(default_factory=list)
    velocities: list[np.ndarray] = field(default_factory=list)
    status: list[int] = field(default_factory=list)
    condition: list[float] = field(default_factory=list)
    scale: list[float] = field(default_factory=list)
    publish: list[bool] = field(default_factory=list)
    messages: list[str] = field(default_factory=list)

    @property
    def q(self) -> np.ndarray:
        return np.array(self.positions)

    @property
    def dq(self) -> np.ndarray:
        return np.array(self.velocities)


class PerfectArm:
    """Drives a JogCalcs in simulated time; the measured state is the last published position."""

    def __init__(self, jog: JogCalcs, start: tuple[float, ...]) -> None:
        self.jog = jog
        self.t = 0.0
        self.q = np.array(start, dtype=float)
        jog.set_joint_state(self.q)

    def run(
        self, cycles: int, twist: tuple[float, ...] | None = None, frame: str = "", trace: Trace | None = None
    ) -> Trace:
        """Runs `cycles` cycles, sending `twist` before each one (None: send nothing)."""
        trace = trace or Trace()
        period = self.jog.settings.pub_period
        for _ in range(cycles):
            if twist is not None:
                self.jog.set_command(twist, frame, self.t)
            out = self.jog.step(self.t)
            if out.publish:
                self.q = np.array(out.positions)
                self.jog.set_joint_state(self.q)
            trace.positions.append(self.q.copy())
            trace.velocities.append(np.array(out.velocities) if out.publish else np.zeros(self.jog.nv))
            trace.status.append(int(out.status))
            trace.condition.append(out.condition_number)
            trace.scale.append(out.speed_scale)
            trace.publish.append(out.publish)
            trace.messages.append(out.message)
            self.t += period
        return trace

    def eef(self) -> np.ndarray:
        return self.jog.eef_pose(self.q).translation.copy()

    def eef_rotation(self) -> np.ndarray:
        return self.jog.eef_pose(self.q).rotation.copy()


def angle_deg(a: np.ndarray, b: np.ndarray) -> float:
    """Angle between two vectors in degrees."""
    cos = float(np.dot(a, b) / (np.linalg.norm(a) * np.linalg.norm(b)))
    return float(np.degrees(np.arccos(np.clip(cos, -1.0, 1.0))))


def ur5_launch_override(directory: pathlib.Path, topics: str) -> pathlib.Path:
    """An override YAML for jog_arm.launch: the UR5 tip, unitless twists (scale 0.1 m/s, 0.3 rad/s) in,
    Float64MultiArray out every 4 ms; topics `topics`/joint_states, /twist and /speed."""
    path = directory / "ur5_jog.yaml"
    path.write_text(
        "ee_frame_name: tool0\nplanning_frame: base_link\ncommand_in_type: unitless\n"
        "scale: {linear: 0.1, rotational: 0.3}\ncommand_out_type: velocity_array\n"
        f"joint_topic: {topics}/joint_states\ncmd_in_topic: {topics}/twist\ncmd_out_topic: {topics}/speed\n"
        "pub_period: 0.004\nincoming_cmd_timeout: 0.5\nintegrate_from: measured\n"
    )
    return path

