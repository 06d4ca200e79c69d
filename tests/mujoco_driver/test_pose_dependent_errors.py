"""Physical pose-dependent errors of the emulated drivers' wrench (no ROS): a payload set wrong on a
payload-compensating controller, and a joint-torque model error seen through the Jacobian; their profile
options, their refusal on a raw sensor, and the unchanged numbers of the other errors for a given seed."""

from __future__ import annotations

import dataclasses

import numpy as np
import pinocchio as pin
import pytest
from mujoco_driver.emulation import DriverEmulation
from mujoco_driver.profiles import ProfileError, WrenchSpec, load_profile
from mujoco_driver.wrench_models import (
    WrenchModel,
    gravity_wrench,
    set_payload_weight,
    wrench_from_joint_torques,
)

G = 9.81
DOWN = np.diag([1.0, -1.0, -1.0])  # tool z along world -z
TILTED = np.array([[0.0, 0.0, 1.0], [0.0, 1.0, 0.0], [-1.0, 0.0, 0.0]])  # 90 deg: tool z along world +x
MASS, COM_IN_TOOL = 1.0, np.array([0.0, 0.0, 0.05])  # the true tool
FRAME_LINK = {"ur5_custom": "tool0", "panda_custom": "panda_link8"}


def _at_rest(spec: WrenchSpec, rotation: np.ndarray) -> np.ndarray:
    """The published wrench of a tool at rest (the sensor reads its true weight), frame at the origin."""
    origin = np.zeros(3)
    com = rotation @ COM_IN_TOOL
    weight = gravity_wrench(MASS, com, origin, rotation)
    payload = set_payload_weight(spec, MASS, com, origin, rotation)
    return WrenchModel(spec, 6)(weight, weight, np.zeros(6), payload=payload).copy()


# ------------------------------------------------------------ payload set wrong
def test_a_wrong_payload_mass_leaves_its_weight_turning_with_the_tool():
    spec = WrenchSpec("w", "f", "l", model="payload_compensated", payload_mass_error=0.3)
    down, tilted = _at_rest(spec, DOWN), _at_rest(spec, TILTED)
    # Set 0.3 kg too heavy: the controller removes 2.94 N too much, which reads as a lift against gravity.
    for rotation, wrench in ((DOWN, down), (TILTED, tilted)):
        np.testing.assert_allclose(rotation @ wrench[:3], [0.0, 0.0, 0.3 * G], atol=1e-12)
    np.testing.assert_allclose(down[:3], [0.0, 0.0, -0.3 * G], atol=1e-12)
    np.testing.assert_allclose(tilted[:3], [-0.3 * G, 0.0, 0.0], atol=1e-12)
    np.testing.assert_allclose(np.abs(tilted[:3] - down[:3]), [2.943, 0.0, 2.943], atol=1e-12)
    # Its torque about the frame's origin: the extra weight at the tool's CoM (zero when it hangs under it).
    np.testing.assert_allclose(down[3:], 0.0, atol=1e-12)
    extra_weight = TILTED.T @ [0.0, 0.0, -0.3 * G]
    np.testing.assert_allclose(tilted[3:], -np.cross(COM_IN_TOOL, extra_weight), atol=1e-12)
    assert abs(tilted[4]) == pytest.approx(0.05 * 0.3 * G)
    right = dataclasses.replace(spec, payload_mass_error=0.0)
    for rotation in (DOWN, TILTED):
        np.testing.assert_allclose(_at_rest(right, rotation), 0.0, atol=1e-12)


def test_a_wrong_payload_centre_of_mass_gives_the_torque_of_the_set_weight_about_it():
    com_error = np.array([0.02, -0.01, 0.0])  # in the tool frame
    spec = WrenchSpec("w", "f", "l", model="external_estimate", payload_com_error=tuple(com_error))
    for rotation in (DOWN, TILTED):
        gravity_in_tool = rotation.T @ [0.0, 0.0, -G]
        wrench = _at_rest(spec, rotation)
        np.testing.assert_allclose(wrench[:3], 0.0, atol=1e-12)
        np.testing.assert_allclose(wrench[3:], -np.cross(com_error, MASS * gravity_in_tool), atol=1e-12)
    assert np.linalg.norm(_at_rest(spec, DOWN)[3:]) == pytest.approx(np.hypot(0.02, 0.01) * G)
    # Both errors: minus the set payload's weight and torque plus the true tool's.
    both = dataclasses.replace(spec, payload_mass_error=-0.2)
    gravity_in_tool = TILTED.T @ [0.0, 0.0, -G]
    expected_torque = -(np.cross(COM_IN_TOOL + com_error, 0.8 * gravity_in_tool)
                        - np.cross(COM_IN_TOOL, MASS * gravity_in_tool))
    np.testing.assert_allclose(_at_rest(both, TILTED)[3:], expected_torque, atol=1e-12)


def test_the_emulated_ur_reads_a_wrong_payload_as_a_world_fixed_lift(sim, robot):
    if robot.package != "ur5_custom":
        pytest.skip("the payload-compensated driver is the UR's")
    emu = DriverEmulation(sim, load_profile("ur_robot_driver", {"payload_mass_error": 0.3}))
    q0 = sim.qpos.copy()
    readings = []
    for turn in (0.0, np.pi / 2):  # the tool down, then turned 90 deg by wrist_2
        sim.set_position_targets(q0 + np.array([0.0, 0.0, 0.0, 0.0, turn, 0.0]))
        sim.step(1000)
        assert not sim.tool_contacts()
        emu.update(sim.wrench())
        r_f = sim.data.xmat[sim.model.body("tool0").id].reshape(3, 3)
        np.testing.assert_allclose(r_f @ emu.wrench[:3], [0.0, 0.0, 0.3 * G], atol=0.01)
        readings.append(emu.wrench[:3].copy())
    assert np.linalg.norm(readings[1] - readings[0]) == pytest.approx(np.sqrt(2) * 0.3 * G, rel=0.01)


# ------------------------------------------------------- joint-torque model error
def _frame_jacobian(robot, link: str, q: np.ndarray) -> np.ndarray:
    """The frame's Jacobian in its own axes about its origin, from Pinocchio (independent of MuJoCo)."""
    data = robot.pin_model.createData()
    frame = robot.pin_model.getFrameId(link)
    return pin.computeFrameJacobian(robot.pin_model, data, q, frame, pin.LOCAL)


def _estimate_profile(robot, torque_error: float):
    """The robot's driver profile, for the UR turned into a joint-torque estimate (the Panda's already is)."""
    if robot.package == "panda_custom":
        return load_profile("franka_ros", {"torque_error": torque_error})
    profile = load_profile("ur_robot_driver")
    wrench = dataclasses.replace(profile.wrench, model="external_estimate", sign=-1.0,
                                 torque_error=torque_error, noise_force=0.4, drift_force=0.2,
                                 drift_time_constant=0.05, seed=7)
    return dataclasses.replace(profile, wrench=wrench)


def test_a_joint_torque_model_error_reads_as_its_least_squares_wrench(sim, robot):
    """The published error is the sign times pinv(J^T) tau_err(q), a few N for 0.5 Nm, varying with q."""
    with_error = DriverEmulation(sim, _estimate_profile(robot, 0.5))
    without = DriverEmulation(sim, _estimate_profile(robot, 0.0))
    q0 = sim.qpos.copy()
    errors = []
    for joint, turn in ((3, 0.0), (3, 0.6)):
        q = q0.copy()
        q[joint] += turn
        sim.set_position_targets(q)
        sim.step(750)
        assert not sim.tool_contacts()
        sensor = sim.wrench()
        with_error.update(sensor)
        without.update(sensor)
        error = with_error.wrench - without.wrench  # the same seed: the same noise and drift
        tau_err = with_error.model.torque_error(sim.qpos)
        assert np.all(np.abs(tau_err) <= 0.5) and np.abs(tau_err).max() > 0.1
        jacobian = _frame_jacobian(robot, FRAME_LINK[robot.package], sim.qpos)
        np.testing.assert_allclose(error, -np.linalg.pinv(jacobian.T) @ tau_err, atol=1e-6)
        assert 0.2 < np.linalg.norm(error[:3]) < 5.0
        errors.append(error)
    assert np.linalg.norm(errors[1] - errors[0]) > 0.1


def test_the_least_squares_wrench_is_the_pseudo_inverse_and_stays_bounded_at_a_singularity():
    rng = np.random.default_rng(0)
    jacobian = rng.normal(size=(6, 7)) * 0.5
    torques = rng.normal(size=7)
    np.testing.assert_allclose(wrench_from_joint_torques(jacobian, torques),
                               np.linalg.pinv(jacobian.T) @ torques, atol=1e-12)
    u, s, vt = np.linalg.svd(jacobian, full_matrices=False)
    for smallest in (0.05, 1e-3, 0.0):  # one direction nearly or fully lost (an outstretched arm)
        singular = u @ np.diag(np.r_[s[:5], smallest]) @ vt
        wrench = wrench_from_joint_torques(singular, torques)
        assert np.all(np.isfinite(wrench)) and np.linalg.norm(wrench) < 13.0 * np.linalg.norm(torques)


def test_a_torque_error_needs_the_jacobian():
    model = WrenchModel(WrenchSpec("w", "f", "l", model="external_estimate", torque_error=0.5), 7)
    with pytest.raises(ValueError, match="Jacobian"):
        model(np.zeros(6), np.zeros(6), np.zeros(7))


# ------------------------------------------------- defaults keep the numbers
_ERRORS = {"model": "external_estimate", "sign": -1.0, "offset_force": 1.5, "offset_torque": 0.3,
           "noise_force": (0.025, 0.0, 0.01), "noise_torque": 0.002, "drift_force": (0.13, 0.12, 0.16),
           "drift_torque": 0.02, "drift_time_constant": 0.041, "contact_shift_threshold": 20.0,
           "contact_shift_fraction": 0.1, "seed": 1}
# This model's first six wrenches (below) before the physical errors were added.
_BEFORE = np.array([
    [1.6350036843870357, -1.3349320943982899, 0.054639730854627033, -0.030341504116251819,
     -0.31544054406561023, 0.22937397430514123],
    [1.5677376695121268, -1.3359701250175082, -0.18667533210372714, 0.0076944176111813107,
     -0.28530339227189389, 0.21259344625757370],
    [1.5436120425188100, -1.4906763366601992, 30.077615937072874, 0.033911006971480216,
     -0.32039071582454887, 0.18407578272818270],
    [1.5932549291854168, -1.4823648738258546, 30.104161823940178, 0.052700920199319823,
     -0.28978634658092817, 0.14108741093537402],
    [1.2919329502820991, -0.13520239776741905, 2.5955208683704138, 0.10972564374752926,
     -0.29368992270410144, 0.13542434999825062],
    [1.2782601720401114, -0.13998170055239934, 2.8604076469930533, 0.14172510040228306,
     -0.31882322888950615, 0.090543790655788048],
])


def _sequence(spec: WrenchSpec, jacobian: np.ndarray | None = None) -> np.ndarray:
    model = WrenchModel(spec, 7, 1.0 / 30.0)
    weight = np.array([0.0, 0.0, -9.81, 0.1, -0.2, 0.0])
    out = []
    for k in range(6):
        q = np.linspace(-1.0, 1.0, 7) * 0.3 * k
        press = np.array([0.0, 0.0, -30.0 if k in (2, 3) else 0.0, 0.0, 0.0, 0.0])
        wrench = model(weight + press, weight, q, jacobian)
        if jacobian is not None:  # remove the torque error: what is left must be the old sequence
            wrench = wrench + wrench_from_joint_torques(jacobian, model.torque_error(q))
        out.append(wrench.copy())
    return np.array(out)


def test_the_same_seed_gives_the_same_wrenches_as_before_with_or_without_a_torque_error():
    np.testing.assert_allclose(_sequence(WrenchSpec("w", "f", "l", **_ERRORS)), _BEFORE, rtol=1e-13, atol=0)
    # A torque error draws from its own stream: the noise, drift, offset and shifts keep their numbers.
    jacobian = np.random.default_rng(2).normal(size=(6, 7))
    spec = WrenchSpec("w", "f", "l", torque_error=0.5, **_ERRORS)
    np.testing.assert_allclose(_sequence(spec, jacobian), _BEFORE, atol=1e-12)


# ------------------------------------------------------------- profile options
def _profile_file(tmp_path, wrench_keys: str) -> str:
    path = tmp_path / "mine.yaml"
    path.write_text(f"driver: x\npublish_rate: 10\njoint_states_topic: js\n"
                    f"wrench: {{topic: w, frame: f, frame_link: l, {wrench_keys}}}\n")
    return str(path)


@pytest.mark.parametrize("key, value, model", [
    ("payload_mass_error", 0.3, "sensor"),
    ("payload_com_error", [0.0, 0.0, 0.01], "sensor"),
    ("torque_error", 0.5, "sensor"),
    ("torque_error", 0.5, "payload_compensated"),
])
def test_an_error_the_model_cannot_have_is_refused_by_name(tmp_path, key, value, model):
    with pytest.raises(ProfileError, match=rf"mine\.yaml\.wrench\.{key}: only for .*not '{model}'"):
        load_profile(_profile_file(tmp_path, f"model: {model}, {key}: {value}"))


@pytest.mark.parametrize("key, value, words", [
    ("payload_mass_error", "heavy", "finite number"),
    ("payload_com_error", [0.0, 0.01], "three numbers"),
    ("torque_error", -0.5, ">= 0"),
])
def test_bad_physical_error_values_are_refused_by_name(tmp_path, key, value, words):
    with pytest.raises(ProfileError, match=rf"wrench\.{key}: .*{words}"):
        load_profile(_profile_file(tmp_path, f"model: external_estimate, {key}: {value}"))


def test_the_options_reach_the_wrench_spec_and_default_to_none():
    ur = load_profile("ur_robot_driver", {"payload_mass_error": 0.3, "payload_com_error": [0.0, 0.0, 0.02]})
    assert ur.wrench.payload_mass_error == 0.3 and ur.wrench.payload_com_error == (0.0, 0.0, 0.02)
    light = load_profile("ur_robot_driver", {"series": "e_series", "payload_mass_error": -0.3}).wrench
    assert light.payload_mass_error == -0.3 and light.noise_force[0] > 0.1  # with the variant's errors
    assert load_profile("franka_ros", {"torque_error": 0.5}).wrench.torque_error == 0.5
    for name, options in (("ur_robot_driver", {}), ("ur_robot_driver", {"series": "cb3_estimate"}),
                          ("franka_ros", {})):
        spec = load_profile(name, options).wrench
        assert spec.payload_mass_error == 0.0 and spec.payload_com_error == (0.0, 0.0, 0.0)
        assert spec.torque_error == 0.0
    with pytest.raises(ProfileError, match="unknown option 'torque_error'"):
        load_profile("ur_robot_driver", {"torque_error": 0.5})
    # The UR's offset over the joints: off unless asked; the current estimate keeps its own 5 N.
    assert load_profile("ur_robot_driver", {}).wrench.offset_force == 0.0
    e_series = load_profile("ur_robot_driver", {"series": "e_series", "offset_force": 3.0}).wrench
    assert e_series.offset_force == 3.0
    assert load_profile("ur_robot_driver", {"series": "cb3_estimate"}).wrench.offset_force == 5.0
