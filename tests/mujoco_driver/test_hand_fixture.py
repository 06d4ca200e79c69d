"""The hand fixture (ISO/TS 15066's hand: 0.6 kg, 75 N/mm) lies on the block, clear of the arm at its start,
gives 1 mm under 75 N, and a tool driven down onto it clamps it against the block beyond the hand's
quasi-static limit (140 N: 1.87 mm), as far as the arm's joint efforts go. The free hand (in the block's
place, nothing under it) struck at 0.5 m/s peaks at ISO/TS 15066's transient force for that speed and
moves away."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pinocchio as pin
import pytest
from mujoco_driver.fixtures import free_hand
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


def _strike(robot, speed: float) -> tuple[np.ndarray, float, float]:
    """The free hand struck from above at `speed` [m/s], the arm going on for 20 ms after |F| passes 20 N
    (through the strike), then stopped: the force magnitude of every step from the touch on (2 ms), the
    tool's speed just before and the hand's lowest."""
    block = robot.cfg.obstacle
    sim = Simulation(robot.urdf, dataclasses.replace(robot.cfg, obstacle=None, hand=free_hand(block)))
    sim.reset()
    model = robot.pin_model
    pin_data = model.createData()
    tip = model.getFrameId(robot.cfg.links.eef)
    slide = int(sim.model.jnt_qposadr[sim.model.joint(HAND_JOINT).id])

    def jog(vz: float) -> None:
        jac = pin.computeFrameJacobian(model, pin_data, sim.qpos, tip, pin.LOCAL_WORLD_ALIGNED)
        sim.set_velocity_targets(np.linalg.lstsq(jac, [0.0, 0.0, vz, 0.0, 0.0, 0.0], rcond=None)[0])

    for _ in range(750):  # 0.3 m up: room to reach the speed
        jog(0.2)
        sim.step(1)
    sim.set_velocity_targets(np.zeros(len(sim.qpos)))
    sim.step(500)
    weight = sim.wrench()[:3].copy()
    forces, z = [], [sim.eef_pose()[0][2]]
    while not forces and sim.time < 6.0:
        jog(-speed)
        sim.step(1)
        z.append(sim.eef_pose()[0][2])
        if np.linalg.norm(sim.wrench()[:3] - weight) > 20.0:
            forces.append(20.0)
    assert forces, "the tool never reached the hand"
    approach = (z[-3] - z[-2]) / sim.dt
    lowest = 0.0
    for k in range(250):
        if k < 10:
            jog(-speed)
        elif k == 10:
            sim.set_velocity_targets(np.zeros(len(sim.qpos)))
        sim.step(1)
        forces.append(float(np.linalg.norm(sim.wrench()[:3] - weight)))
        lowest = min(lowest, float(sim.data.qpos[slide]))
    return np.array(forces), approach, lowest


def test_a_struck_free_hand_peaks_at_annex_a_transient_force_and_moves_away(robot):
    """ISO/TS 15066 A.5: a transient contact at v peaks at v sqrt(mu k), mu the reduced mass of the hand
    (0.6 kg) and the tool (its effective mass, 4-5 kg down for both arms: jog_arm README's table)."""
    hand = Hand()
    forces, approach, lowest = _strike(robot, 0.5)
    mu_bounds = [1.0 / (1.0 / hand.mass + 1.0 / m) for m in (4.0, math.inf)]
    expected = [approach * math.sqrt(mu * hand.stiffness) for mu in mu_bounds]
    print(f"\n{robot.package}: struck at {approach:.3f} m/s: peak {forces.max():.1f} N "
          f"(Annex A {expected[0]:.0f}-{expected[1]:.0f} N), the hand {-lowest * 1e3:.0f} mm down")
    assert approach == pytest.approx(0.5, rel=0.02)
    assert 0.9 * expected[0] < forces[:10].max() < 1.1 * expected[1]
    assert lowest < -0.01  # it moved away: not pinned
    assert forces[-50:].max() < 140.0  # nothing clamped it afterwards


def test_the_free_hand_fixture_takes_the_block_place(tmp_path):
    from mujoco_driver.params import DriverParamError, DriverSettings, load_scene

    scene = {"start_pose": [0.0], "servo": {"kp": 1.0, "kv": 1.0}, "obstacle": {"position": [0.5, 0.0, 0.05],
                                                                               "size": [0.1, 0.1, 0.1]}}
    cfg = load_scene(DriverSettings.from_params({"fixture": "free_hand", "scene": scene}))
    assert cfg.obstacle is None and cfg.hand is not None and cfg.hand.free
    assert cfg.hand.at == pytest.approx((0.5, 0.0, 0.1 - Hand().size[2]))
    del scene["obstacle"]
    with pytest.raises(DriverParamError, match="no obstacle block to put the hand in place of"):
        load_scene(DriverSettings.from_params({"fixture": "free_hand", "scene": scene}))
