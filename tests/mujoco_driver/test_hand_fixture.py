"""The hand fixture (ISO/TS 15066's hand: 0.6 kg, 75 N/mm) lies on the block, clear of the arm at its start,
gives 1 mm under 75 N, and a tool driven down onto it clamps it against the block beyond the hand's
quasi-static limit (140 N: 1.87 mm), as far as the arm's joint efforts go."""

from __future__ import annotations

import dataclasses

import numpy as np
import pinocchio as pin
import pytest
from mujoco_driver.scene import HAND_BODY, HAND_JOINT
from mujoco_driver.sim import Simulation

from mujoco_driver.config import Hand

pytestmark = pytest.mark.cobot_safety


@pytest.fixture(scope="module")
def hand_sim(robot):
    return Simulation(robot.urdf, dataclasses.replace(robot.cfg, hand=Hand()))


def test_the_hand_rests_on_the_block_and_gives_a_millimetre_under_75_newtons(robot, hand_sim):
    sim = hand_sim
    sim.reset()
    model, data = sim.model, sim.data
    body, slide = model.body(HAND_BODY).id, int(model.jnt_qposadr[model.joint(HAND_JOINT).id])
    sim.step(200)
    top = robot.cfg.obstacle.position[2] + robot.cfg.obstacle.size[2] / 2
    assert data.xpos[body][2] == pytest.approx(top + Hand().size[2] / 2, abs=1e-5)  # weightless: at rest
    assert not sim.tool_contacts()
    data.xfrc_applied[body] = [0.0, 0.0, -75.0, 0.0, 0.0, 0.0]
    sim.step(1000)
    assert data.qpos[slide] == pytest.approx(-0.001, rel=0.01)
    data.xfrc_applied[body] = 0.0


def test_a_tool_driven_down_onto_the_hand_presses_it_against_the_block(robot, hand_sim):
    sim = hand_sim
    sim.reset()
    model = robot.pin_model
    pin_data = model.createData()
    tip = model.getFrameId(robot.cfg.links.eef)
    slide = int(sim.model.jnt_qposadr[sim.model.joint(HAND_JOINT).id])
    down = np.array([0.0, 0.0, -0.05, 0.0, 0.0, 0.0])
    while HAND_BODY not in sim.tool_contacts() and sim.time < 3.0:
        jac = pin.computeFrameJacobian(model, pin_data, sim.qpos, tip, pin.LOCAL_WORLD_ALIGNED)
        sim.set_velocity_targets(np.linalg.lstsq(jac, down, rcond=None)[0])
        sim.step(5)
    assert HAND_BODY in sim.tool_contacts(), "the tool never reached the hand"
    for _ in range(40):  # 0.4 s more at 5 cm/s: 20 mm into it, more than the arm's efforts can press
        jac = pin.computeFrameJacobian(model, pin_data, sim.qpos, tip, pin.LOCAL_WORLD_ALIGNED)
        sim.set_velocity_targets(np.linalg.lstsq(jac, down, rcond=None)[0])
        sim.step(5)
    assert sim.data.qpos[slide] < -140.0 / Hand().stiffness  # clamped past 140 N, not pushed aside


def test_the_fixture_parameter_lays_the_hand_and_needs_a_block(tmp_path):
    from mujoco_driver.params import DriverParamError, DriverSettings, load_scene

    scene = {"start_pose": [0.0], "servo": {"kp": 1.0, "kv": 1.0}, "obstacle": {"position": [0.5, 0.0, 0.05],
                                                                               "size": [0.1, 0.1, 0.1]}}
    cfg = load_scene(DriverSettings.from_params({"fixture": "hand", "scene": scene}))
    assert cfg.hand == Hand()
    del scene["obstacle"]
    with pytest.raises(DriverParamError, match="no obstacle block to lay the hand on"):
        load_scene(DriverSettings.from_params({"fixture": "hand", "scene": scene}))
