"""A cell: a UR5 and a Panda in one MuJoCo world, each seen through its own Simulation as if alone."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pinocchio as pin
import pytest
from harness.description import make_description
from mujoco_driver.cell import CellArm, World
from mujoco_driver.scene import SceneError

from mujoco_driver.config import load_scene_config

from .conftest import ROBOTS, ROOT, Robot

# The Panda 1.5 m along world y, turned a quarter about z: its base x is the world's y.
PLACES = {"left": ((0.0, 0.0, 0.0), (0.0, 0.0, 0.0)), "right": ((0.0, 1.5, 0.0), (0.0, 0.0, math.pi / 2))}


@pytest.fixture(scope="module")
def robots() -> dict[str, Robot]:
    found = {}
    for name, package in zip(PLACES, ROBOTS, strict=True):
        config_dir = ROOT / "src" / package / "config"
        result = make_description(f"@{config_dir / 'description.args'}")
        assert result.returncode == 0, result.stderr
        found[name] = Robot(package, result.stdout, load_scene_config(str(config_dir / "sim.yaml")),
                            pin.buildModelFromXML(result.stdout))
    return found


@pytest.fixture(scope="module")
def shared_world(robots: dict[str, Robot]) -> World:
    return World([CellArm(name, robots[name].urdf, robots[name].cfg, *PLACES[name]) for name in PLACES])


@pytest.fixture
def world(shared_world: World) -> World:
    shared_world.reset()
    return shared_world


def _seconds(world: World, seconds: float) -> None:
    world.step(round(seconds / world.dt))


def test_each_arm_holds_its_start_and_sees_its_pose_and_weight_as_it_does_alone(world, robots):
    _seconds(world, 1.0)
    assert world.time == pytest.approx(1.0)
    assert world.data.warning[0].number == 0 and all(w.number == 0 for w in world.data.warning)
    for name, arm in world.arms.items():
        alone = robots[name].simulation()
        alone.step(round(1.0 / alone.dt))
        np.testing.assert_allclose(arm.qpos, alone.qpos, atol=1e-5)
        np.testing.assert_allclose(arm.eef_pose()[0], alone.eef_pose()[0], atol=1e-5)
        assert abs(np.dot(arm.eef_pose()[1], alone.eef_pose()[1])) == pytest.approx(1.0, abs=1e-8)
        np.testing.assert_allclose(arm.sensor_rotation(), alone.sensor_rotation(), atol=1e-6)
        np.testing.assert_allclose(arm.wrench(), alone.wrench(), atol=0.05)
    # In the world, the Panda's tool is where its base pose puts it.
    panda = world.arms["right"]
    tip_world = world.data.xpos[panda.scene.eef_body]
    x, y, z = panda.eef_pose()[0]
    np.testing.assert_allclose(tip_world, [-y, 1.5 + x, z], atol=1e-9)


def test_a_command_moves_only_its_own_arm(world):
    left, right = world.arms["left"], world.arms["right"]
    right_start = right.qpos
    qd = np.zeros(len(left.joint_names))
    qd[0] = 0.2
    left.set_velocity_targets(qd)
    _seconds(world, 0.5)
    assert left.qpos[0] - left.scene.start_pose[0] == pytest.approx(0.2 * 0.5, abs=0.01)
    np.testing.assert_allclose(right.qpos, right_start, atol=1e-5)


def test_a_push_in_an_arms_base_frame_moves_its_tool_along_that_frame(world):
    panda = world.arms["right"]
    tip = panda.eef_pose()[0]
    panda.push((10.0, 0.0, 0.0), duration=0.3)
    _seconds(world, 0.3)
    force = panda.sensor_rotation() @ panda.wrench()[:3]
    assert force[0] > 5.0 and abs(force[1]) < 2.0, "the push reads along the base's x on its sensor"
    moved = panda.eef_pose()[0] - tip
    assert moved[0] > 0.0 and abs(moved[1]) < abs(moved[0]), "the tool yields along its base's x"


def test_an_arm_touching_its_own_block_names_it_as_it_does_alone(robots):
    """The UR5's block raised 7.5 cm: its top 5 mm into the tool at the start pose."""
    ur5, panda = robots["left"], robots["right"]
    block = ur5.cfg.obstacle
    raised = dataclasses.replace(ur5.cfg, obstacle=dataclasses.replace(
        block, position=(block.position[0], block.position[1], block.position[2] + 0.075)))
    world = World([CellArm("left", ur5.urdf, raised),
                   CellArm("right", panda.urdf, panda.cfg, *PLACES["right"])])
    world.step()
    assert "obstacle" in world.arms["left"].tool_contacts()
    assert world.arms["right"].tool_contacts() == set()


def test_resetting_one_arm_leaves_the_other_where_it_is(world):
    left, right = world.arms["left"], world.arms["right"]
    for arm in (left, right):
        qd = np.zeros(len(arm.joint_names))
        qd[0] = 0.2
        arm.set_velocity_targets(qd)
    _seconds(world, 0.5)
    right_before = right.qpos
    left.reset()
    np.testing.assert_allclose(left.qpos, left.scene.start_pose, atol=1e-9)
    np.testing.assert_allclose(right.qpos, right_before, atol=1e-9)
    assert world.time == pytest.approx(0.5), "the world's time goes on"


def test_a_bad_cell_is_refused_naming_the_arm(robots):
    ur5 = robots["left"]
    with pytest.raises(SceneError, match="distinct names"):
        World([CellArm("a", ur5.urdf, ur5.cfg), CellArm("a", ur5.urdf, ur5.cfg, (2.0, 0.0, 0.0))])
    slower = dataclasses.replace(ur5.cfg, timestep=0.001)
    with pytest.raises(SceneError, match=r"arm b: timestep 0\.001 s"):
        World([CellArm("a", ur5.urdf, ur5.cfg), CellArm("b", ur5.urdf, slower, (2.0, 0.0, 0.0))])
    with pytest.raises(SceneError, match=r"arm b: links\.tool"):
        World([CellArm("a", ur5.urdf, ur5.cfg),
               CellArm("b", ur5.urdf, dataclasses.replace(ur5.cfg, links=dataclasses.replace(
                   ur5.cfg.links, tool="no_such_link")), (2.0, 0.0, 0.0))])
