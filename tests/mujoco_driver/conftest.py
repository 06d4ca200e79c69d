"""Fixtures: the two robots' descriptions (from their packages' description.args) and scene configs."""

from __future__ import annotations

import pathlib
from dataclasses import dataclass

import pinocchio as pin
import pytest
from harness.description import make_description
from mujoco_driver.sim import Simulation

from mujoco_driver.config import SceneConfig, load_scene_config

ROOT = pathlib.Path(__file__).resolve().parents[2]
ROBOTS = ("ur5_custom", "panda_custom")


@dataclass
class Robot:
    """One robot package's data: URDF text, scene settings and a Pinocchio model of the URDF."""

    package: str
    urdf: str
    cfg: SceneConfig
    pin_model: pin.Model

    def simulation(self) -> Simulation:
        return Simulation(self.urdf, self.cfg)


@pytest.fixture(scope="session", params=ROBOTS)
def robot(request: pytest.FixtureRequest) -> Robot:
    config_dir = ROOT / "src" / request.param / "config"
    result = make_description(f"@{config_dir / 'description.args'}")
    assert result.returncode == 0, result.stderr
    return Robot(
        package=request.param,
        urdf=result.stdout,
        cfg=load_scene_config(str(config_dir / "sim.yaml")),
        pin_model=pin.buildModelFromXML(result.stdout),
    )


@pytest.fixture(scope="session")
def shared_sim(robot: Robot) -> Simulation:
    """One simulation per robot for the session (tests call reset() first)."""
    return robot.simulation()


@pytest.fixture
def sim(shared_sim: Simulation) -> Simulation:
    shared_sim.reset()
    return shared_sim
