"""A robot whose URDF has joints outside the arm (TIAGo: mobile base wheels, torso lift, head): the scene
holds them where `held_joints` says, velocity commands address the arm's joints only, and links whose meshes
overlap in every posture (TIAGo's torso column and first arm link) do not push the arm from its start."""

from __future__ import annotations

import numpy as np
import pytest
from control_stack.description import ToolSpec, build_description, find_example_robot_data, read_source
from mujoco_driver.scene import SceneError, build_scene
from mujoco_driver.sim import CommandError, Simulation

from mujoco_driver.config import ConfigError, SceneConfig

ARM = [f"arm_{i}_joint" for i in range(1, 8)]
HELD = {"wheel_right_joint": 0.0, "wheel_left_joint": 0.0, "torso_lift_joint": 0.15, "head_1_joint": 0.3,
        "head_2_joint": -0.2}
START = [1.7244, -0.138, 0.7028, 1.1409, -0.2884, 0.7312, 0.6488]  # tiago_custom's start pose


@pytest.fixture(scope="module")
def urdf() -> str:
    erd = find_example_robot_data()
    tool = ToolSpec(parent="arm_tool_link", mass=1.0, com=(0.0, 0.0, 0.05), size=(0.03, 0.12),
                    ft_rpy=(0.0, 1.5708, 0.0))
    stock = read_source("example-robot-data:robots/tiago_description/robots/tiago_no_hand.urdf", erd)
    return build_description(stock, tool, ("wrist_ft_link",), erd)


def _config(**changes) -> SceneConfig:
    data = {"start_pose": dict(zip(ARM, START, strict=True)),
            "held_joints": [{k: v} for k, v in HELD.items()],
            "servo": {"kp": 1000.0, "kv": 20.0, "armature": 0.1, "max_acceleration": 4.0}, **changes}
    return SceneConfig.from_dict(data)


def test_held_joints_stay_while_the_arm_moves(urdf):
    sim = Simulation(urdf, _config())
    assert sim.arm_joint_names == tuple(ARM)
    assert set(sim.joint_names) == set(ARM) | set(HELD)
    held = [sim.joint_names.index(n) for n in HELD]
    arm = [sim.joint_names.index(n) for n in ARM]
    assert sim.qpos[held] == pytest.approx(list(HELD.values()), abs=1e-9)
    sim.step(500)  # 1 s at rest: nothing pushes the arm from its start (overlapping meshes are left out)
    assert np.max(np.abs(sim.qvel)) < 2e-3, dict(zip(sim.joint_names, sim.qvel, strict=True))
    assert np.max(np.abs(sim.qpos[arm] - START)) < 2e-3
    sim.set_arm_velocity_targets(np.full(7, 0.1))
    sim.step(500)
    assert sim.qpos[arm] - START == pytest.approx(np.full(7, 0.1), abs=0.02)  # 1 s at 0.1 rad/s
    assert sim.qpos[held] == pytest.approx(list(HELD.values()), abs=2e-3)
    with pytest.raises(CommandError, match=r"expected 7 values \(arm joints \['arm_1_joint'"):
        sim.set_arm_velocity_targets(np.zeros(12))


@pytest.mark.parametrize(("changes", "message"), [
    ({"held_joints": [HELD, {"gripper": 0.0}]}, r"held_joints: \['gripper'\] are not movable joints"),
    ({"held_joints": [{**HELD, "torso_lift_joint": 0.5}]},
     r"joints \['torso_lift_joint'\] outside their limits"),
    ({"held_joints": []},
     r"start_pose: joints missing \['wheel_right_joint'.*joints outside the arm go in held_joints"),
])
def test_a_held_joint_that_does_not_fit_the_urdf_is_named(urdf, changes, message):
    with pytest.raises(SceneError, match=message):
        build_scene(urdf, _config(**changes))


@pytest.mark.parametrize(("held", "message"), [
    ([{"head_1_joint": "up"}], "held_joints.head_1_joint: expected a number"),
    (["head_1_joint"], "held_joints: expected a list of <joint>: position entries"),
])
def test_held_joints_must_be_a_list_of_positions(held, message):
    with pytest.raises(ConfigError, match=message):
        SceneConfig.from_dict({"start_pose": 0.0, "servo": {"kp": 1.0, "kv": 0.0}, "held_joints": held})
