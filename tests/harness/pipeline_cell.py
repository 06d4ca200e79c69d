"""A robot package's CompliantPipeline with a perfect arm (no ROS master): the commanded joint velocity
happens exactly, the wrench is generated (tool weight + a push + whatever a test adds)."""

from __future__ import annotations

import math
import pathlib
import subprocess
import sys
from collections.abc import Callable, Sequence

import numpy as np
import yaml
from contact_control.axes import LAW_FOLLOWER
from contact_control.laws import AxisLaw
from contact_control.params import load_settings
from contact_control.stage import Velocity
from control_stack.pipeline import CompliantPipeline, PipelineOutput
from jog_arm.settings import JogSettings

__all__ = ["DT", "SRC", "Cell"]

SRC = pathlib.Path(__file__).resolve().parents[2] / "src"
DT = 0.002  # the robots' 500 Hz wrench and joint state
DAMPING = 30.0  # [N/(m/s)] follower on Z: 4 N -> 0.133 m/s
#: (joint positions, sensor rotation in the fixed frame) -> what the sensor adds to the truth [N, Nm]
SensorError = Callable[[np.ndarray, np.ndarray], Sequence[float]]


def _yaml(path: pathlib.Path) -> dict:
    return yaml.safe_load(path.read_text()) or {}


class Cell:
    """One robot package's pipeline and a perfect arm (the commanded joint velocity happens exactly)."""

    def __init__(
        self, robot: str, params: dict | None = None, sensor_error: SensorError | None = None,
        jog_overrides: dict | None = None,
    ) -> None:
        pkg = SRC / f"{robot}_custom"
        cc = load_settings({**_yaml(SRC / "contact_control/config/contact_control.yaml"),
                            **_yaml(pkg / "config/contact_control.yaml"), **(params or {})})
        self.urdf = ""
        jog_params = {**_yaml(SRC / "jog_arm/config/jog_arm.yaml"), **_yaml(pkg / "config/jog_arm.yaml"),
                      **(jog_overrides or {})}
        jog, _ = JogSettings.from_params_with_warnings(jog_params, "/jog_arm_server/")
        urdf = subprocess.run(
            [sys.executable, str(SRC / "control_stack/scripts/make_description"),
             f"@{pkg / 'config/description.args'}"],
            check=True, capture_output=True, text=True,
        ).stdout
        self.urdf = urdf
        self.sensor_error = sensor_error
        self.pipeline = CompliantPipeline(cc, jog, urdf)
        start = _yaml(pkg / "config/named_poses.yaml")["poses"]["start"]
        self.names = list(self.pipeline.jog.joint_names)
        self.q = np.array([start[n] for n in self.names], dtype=float)
        self.cc = cc
        self.t = 0.0
        self.commands: list[tuple[float, tuple[float, ...]]] = []

    def pose(self, frame: str) -> np.ndarray:
        return np.array(self.pipeline.jog.frames.pose(frame, self.cc.fixed_frame))

    def wrench(self, push_fixed: Sequence[float]) -> tuple[float, ...]:
        """What the sensor reads: the tool's weight and a force [N] given in the fixed frame."""
        R = self.pose(self.cc.ft_sensor_frame)[:3, :3]
        prep = self.pipeline.contact.ctrl.preprocessor
        weight = prep.gravity_wrench(R.tolist())
        force = R.T @ np.asarray(push_fixed, dtype=float)
        oriented = [weight[i] + (force[i] if i < 3 else 0.0) for i in range(6)]
        if self.sensor_error is not None:
            oriented = [a + b for a, b in zip(oriented, self.sensor_error(self.q, R), strict=True)]
        return tuple(prep.oriented(oriented))  # the sign flips are their own inverse

    def _apply(self, out: PipelineOutput) -> None:
        cycle = out.cycle
        if cycle is not None and cycle.publish:
            self.commands.append((self.t, cycle.velocities))
            self.q = self.q + np.asarray(cycle.velocities) * DT

    def step(self, push_fixed: Sequence[float] | None, nan: bool = False) -> Velocity | None:
        """One 2 ms period: the joint state, then the wrench (none if `push_fixed` is None), then tick; the
        twist the wrench gave (None without a wrench, or when none was due)."""
        self.t += DT
        p = self.pipeline
        p.on_joint_state(self.names, self.q.tolist(), self.t)
        twist = None
        if push_fixed is not None:
            wrench = (math.nan,) * 6 if nan else self.wrench(push_fixed)
            out = p.on_wrench(wrench, self.cc.ft_sensor_frame, self.t, self.t)
            twist = out.twist
            self._apply(out)
            p.prepare()
        if self.t >= p.next_due():
            self._apply(p.tick(self.t))
        return twist

    def follower_z(self) -> None:
        laws = [AxisLaw() for _ in range(6)]
        laws[2] = AxisLaw(LAW_FOLLOWER, damping=DAMPING)
        self.pipeline.contact.ctrl.set_laws(laws, None, self.t)


