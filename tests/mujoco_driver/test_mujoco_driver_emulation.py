"""Driver emulation without ROS: profiles, the controller manager, the wrench models, the rate divider, the
reflex, and both robots' simulations speaking as ur_robot_driver and franka_ros."""

from __future__ import annotations

import os
import tempfile

import numpy as np
import pytest
import yaml
from mujoco_driver.controllers import BEST_EFFORT, STRICT, ControllerManager, ControllerSpec
from mujoco_driver.emulation import DriverEmulation
from mujoco_driver.profiles import ProfileError, WrenchSpec, known_profiles, load_profile, option_params
from mujoco_driver.protective_stop import NORMAL, PROTECTIVE_STOP, ProtectiveStop
from mujoco_driver.wrench_models import (
    PeriodMean,
    RateDivider,
    Reflex,
    WrenchModel,
    change_frame,
    gravity_wrench,
)

PROFILE_FOR = {"ur5_custom": "ur_robot_driver", "panda_custom": "franka_ros"}


# ------------------------------------------------------------- profiles
def test_ur_profile_has_the_real_drivers_names_and_rates():
    p = load_profile("ur_robot_driver")
    assert p.publish_rate == 125.0
    assert load_profile("ur_robot_driver", {"series": "e_series"}).publish_rate == 500.0
    assert (p.joint_states_topic, p.wrench.topic) == ("joint_states", "wrench")
    assert p.wrench.frame == "tool0_controller"
    assert p.wrench.model == "payload_compensated" and p.wrench.sign == 1.0
    assert p.wrench.zero_service == "ur_hardware_interface/zero_ftsensor"
    assert p.speed_scaling_topic == "speed_scaling_factor"
    commands = {c.name: (c.command, c.initial_state) for c in p.controllers if c.command != "none"}
    assert commands == {"scaled_pos_joint_traj_controller": ("trajectory", "running"),
                        "joint_group_vel_controller": ("velocity", "initialized")}


def test_franka_profile_resolves_arm_id_and_rate_options():
    p = load_profile("franka_ros")
    assert p.publish_rate == 30.0 and p.wrench.frame == "panda_K" and p.wrench.sign == -1.0
    assert p.joint_states_topic == "franka_state_controller/joint_states"
    assert p.wrench.topic == "franka_state_controller/F_ext"
    assert [t.child for t in p.tf] == ["panda_NE", "panda_EE", "panda_K"]
    assert p.reflex.force_thresholds == (20.0, 20.0, 20.0, 25.0, 25.0, 25.0)
    other = load_profile("franka_ros", {"arm_id": "fr3", "publish_rate": 100.0,
                                        "reflex_force_thresholds": [30.0] * 6})
    assert other.publish_rate == 100.0 and other.wrench.frame == "fr3_K" and other.tf[0].parent == "fr3_link8"
    assert other.reflex.force_thresholds == (30.0,) * 6  # a whole-value placeholder keeps the list
    with pytest.raises(ProfileError, match=r"reflex\.force_thresholds"):
        load_profile("franka_ros", {"reflex_force_thresholds": [30.0] * 5})


def test_the_driver_stops_resolve_and_bad_entries_are_refused_by_key(tmp_path):
    state = load_profile("franka_ros").reflex.state
    assert (state.topic, state.type, state.mode_field) == (
        "franka_state_controller/franka_states", "franka_msgs/FrankaState", "robot_mode")
    assert (state.moving, state.stopped, state.running) == (2, 4, (1, 2))
    assert state.held_flags == ("current_errors.cartesian_reflex",)
    stop = load_profile("ur_robot_driver", {"protective_stop_force": 40.0}).protective_stop
    assert stop.force_limit == 40.0 and stop.unlock_after == 5.0
    base = "driver: d\npublish_rate: 10\njoint_states_topic: j\nwrench: {topic: w, frame: f, frame_link: l}\n"
    bad = [("reflex: {force_thresholds: [1, 1, 1, 1, 1, 1], recovery_action: r, recovery_type: p/RAction, "
            "state: {topic: t, colour: red}}", r"reflex\.state: unknown keys \['colour'\]"),
           ("reflex: {force_thresholds: [1, 1, 1, 1, 1, 1], recovery_action: r, recovery_type: p/RAction, "
            "state: {topic: t, type: p/S, mode_field: m, moving: 2, stopped: 4, running: [1], joints: q, "
            "velocities: dq, wrench: w}}", r"reflex\.state\.running: .*includes `moving`"),
           ("protective_stop: {force_limit: 1, unlock_after: 1, safety_mode_topic: s, robot_mode_topic: r, "
            "program_running_topic: p, unlock_service: u, play_services: []}",
            r"protective_stop\.play_services")]
    for i, (text, message) in enumerate(bad):
        path = tmp_path / f"bad{i}.yaml"
        path.write_text(base + text + "\n")
        with pytest.raises(ProfileError, match=message):
            load_profile(str(path))


def test_known_profiles_are_the_files_in_config_profiles():
    assert known_profiles() == ["franka_ros", "ur_robot_driver"]
    with pytest.raises(ProfileError, match=r"profiles: \['franka_ros', 'ur_robot_driver'\]"):
        load_profile("no_such_driver")


@pytest.mark.parametrize("source, options, message", [
    ("no_such_driver", None, "profiles: ["),
    ("ur_robot_driver", {"speed": 1}, "unknown option 'speed'"),
    ("ur_robot_driver", {"series": "cb2"}, "must be one of"),
    ("franka_ros", {"publish_rate": -5.0}, "publish_rate: must be > 0"),
])
def test_bad_profiles_and_options_are_refused_by_name(source, options, message):
    with pytest.raises(ProfileError, match=message.replace("[", r"\[")):
        load_profile(source, options)


def test_a_profile_file_with_a_bad_key_names_it(tmp_path):
    path = tmp_path / "mine.yaml"
    path.write_text("driver: x\npublish_rate: 10\njoint_states_topic: js\n"
                    "wrench: {topic: w, frame: f, frame_link: l, model: guess}\n")
    with pytest.raises(ProfileError, match=r"mine.yaml.wrench.model"):
        load_profile(str(path))
    path.write_text("driver: x\npublish_rate: 10\njoint_states_topic: js\nwrench: {topic: w, frame: f, "
                    "frame_link: l}\nreflex: {force_thresholds: [1, 2], recovery_action: r}\n")
    with pytest.raises(ProfileError, match="force_thresholds: expected 6 positive"):
        load_profile(str(path))


# --------------------------------------------------- controller manager
def _manager() -> ControllerManager:
    return ControllerManager([
        ControllerSpec("joint_state_controller", "jsc"),
        ControllerSpec("traj", "t", command="trajectory", hardware_interface="pos", initial_state="running"),
        ControllerSpec("vel", "v", command="velocity", hardware_interface="vel", initial_state="initialized"),
    ], ["j1", "j2"])


def test_only_the_running_controller_moves_the_arm_and_a_switch_hands_over():
    cm = _manager()
    assert cm.accepts("traj") and not cm.accepts("vel") and not cm.accepts("unknown")
    result = cm.switch(["vel"], ["traj"], STRICT)
    assert result.ok and result.started == ["vel"] and result.stopped == ["traj"]
    assert cm.accepts("vel") and not cm.accepts("traj")
    assert (cm.state("traj"), cm.state("vel")) == ("stopped", "running")
    listing = {spec.name: (state, joints) for spec, state, joints in cm.listing()}
    assert listing["vel"] == ("running", ["j1", "j2"])
    assert listing["joint_state_controller"] == ("running", [])


def test_starting_a_second_command_controller_is_a_resource_conflict_in_any_strictness():
    cm = _manager()
    for strictness in (STRICT, BEST_EFFORT):
        result = cm.switch(["vel"], [], strictness)
        assert not result.ok and "resource conflict" in result.message
        assert cm.running() == ["joint_state_controller", "traj"]


def test_strict_fails_whole_on_unknown_names_best_effort_skips_them():
    cm = _manager()
    result = cm.switch(["vel", "ghost"], ["traj"], STRICT)
    assert not result.ok and "ghost" in result.message and cm.accepts("traj")
    result = cm.switch(["vel", "ghost"], ["traj"], BEST_EFFORT)
    assert result.ok and "ghost" in result.message and cm.accepts("vel")
    assert not cm.switch([], ["traj"], STRICT).ok  # not running
    assert not cm.switch(["vel"], [], 7).ok


# --------------------------------------------------------- wrench models
def test_change_frame_moves_the_torque_to_the_new_origin():
    rz = np.array([[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]])  # 90 deg about z
    w = np.array([1.0, 0.0, 0.0, 0.0, 0.0, 0.0])
    out = change_frame(w, np.eye(3), np.zeros(3), rz, np.array([0.0, -0.5, 0.0]))
    # Force +X_world is -Y in the rotated frame; 0.5 m off its line: torque 0.5 Nm about -Z_world.
    np.testing.assert_allclose(out, [0.0, -1.0, 0.0, 0.0, 0.0, -0.5], atol=1e-12)


def test_payload_compensation_removes_the_weight_and_the_estimate_flips_sign_with_offset_and_noise():
    weight = gravity_wrench(1.0, np.array([0.0, 0.0, -0.05]), np.zeros(3), np.eye(3))
    np.testing.assert_allclose(weight, [0, 0, -9.81, 0, 0, 0], atol=1e-12)
    push = np.array([10.0, 0, 0, 0, 0, 0])
    spec = WrenchSpec("w", "f", "l", model="payload_compensated")
    np.testing.assert_allclose(WrenchModel(spec, 3)(push + weight, weight, np.zeros(3)), push)
    spec = WrenchSpec("w", "f", "l", model="external_estimate", sign=-1.0, offset_force=3.0,
                      offset_torque=0.3, noise_force=0.4, noise_torque=0.04, seed=1)
    model = WrenchModel(spec, 3)
    samples = np.array([model(push + weight, weight, np.zeros(3)) for _ in range(2000)])
    offset = model.offset(np.zeros(3))
    np.testing.assert_allclose(samples.mean(axis=0), -push + offset, atol=0.05)
    np.testing.assert_allclose(samples[:, :3].std(axis=0), 0.4, rtol=0.1)
    # The offset: bounded by its amplitude, continuous, and different elsewhere in joint space.
    qs = np.linspace(-2.0, 2.0, 401)[:, None] * np.array([1.0, -0.5, 0.3])
    offsets = np.array([model.offset(q) for q in qs])
    assert np.all(np.abs(offsets[:, :3]) <= 3.0) and np.all(np.abs(offsets[:, 3:]) <= 0.3)
    assert np.max(np.abs(np.diff(offsets[:, :3], axis=0))) < 0.02  # 10 mrad apart: within 0.02 N
    assert np.ptp(offsets[:, :3], axis=0).max() > 1.0


def test_zero_makes_the_current_reading_zero():
    spec = WrenchSpec("w", "f", "l", model="payload_compensated")
    model = WrenchModel(spec, 1)
    reading = np.array([1.0, 2.0, 3.0, 0.1, 0.2, 0.3])
    model.zero(model(reading, np.zeros(6), np.zeros(1)))
    np.testing.assert_allclose(model(reading, np.zeros(6), np.zeros(1)), 0.0, atol=1e-12)


@pytest.mark.parametrize("rate, expected", [(30.0, 30), (125.0, 125), (500.0, 500), (1000.0, 500)])
def test_rate_divider_keeps_the_average_rate(rate, expected):
    divider = RateDivider(0.002, rate)
    assert sum(divider.due() for _ in range(500)) == pytest.approx(expected, abs=1)


def test_the_period_mean_keeps_a_contacts_ringing_out_of_a_slower_publication():
    """10 N ringing at 70-240 Hz (the simulated contact's band), simulated at 1 kHz and published at 100 Hz
    (franka_ros's bring-up rate): sampled, the ringing aliases into about 2 N of scatter; the period's mean
    keeps under a fifth of it and the 10 N. The profile turns it on for franka_ros."""
    t = np.arange(0.0, 2.0, 0.001)
    phases = np.random.default_rng(1).uniform(0.0, 2.0 * np.pi, 4)
    ringing = zip((70.0, 130.0, 190.0, 240.0), phases, strict=True)  # [Hz], [rad]
    force = 10.0 + sum(1.5 * np.sin(2.0 * np.pi * f * t + p) for f, p in ringing)
    sampled, averaged, mean = [], [], PeriodMean()
    for k, f in enumerate(force):
        w = np.array([0.0, 0.0, f, 0.0, 0.0, 0.0])
        if (k + 1) % 10:
            mean.add(w)
            continue
        sampled.append(f)
        mean.take(w)
        averaged.append(w[2])
    assert np.std(sampled) > 2.0
    assert np.std(averaged) < 0.2 * np.std(sampled) and np.mean(averaged) == pytest.approx(10.0, abs=0.05)
    assert load_profile("franka_ros").wrench.period_mean
    assert not load_profile("ur_robot_driver", {"series": "e_series"}).wrench.period_mean


def test_protective_stop_trips_on_the_force_magnitude_and_recovers_in_the_drivers_order():
    stop = ProtectiveStop(150.0, 5.0)
    assert stop.safety_mode == NORMAL and stop.program_running
    assert not stop.check(np.array([100.0, -100.0, 0, 9, 9, 9]), 1.0)  # 141 N
    assert stop.check(np.array([110.0, -110.0, 0, 0, 0, 0]), 2.0)  # 156 N
    assert stop.safety_mode == PROTECTIVE_STOP and not stop.program_running and "156 N" in stop.reason
    assert not stop.check(np.full(6, 500.0), 2.1)  # trips once
    assert not stop.play()[0]
    ok, answer = stop.unlock(6.9)
    assert not ok and "5s after occurrence" in answer and stop.safety_mode == PROTECTIVE_STOP
    assert stop.unlock(7.0)[0] and stop.safety_mode == NORMAL and not stop.program_running
    assert stop.play()[0] and stop.program_running
    with pytest.raises(ValueError):
        ProtectiveStop(0.0, 5.0)


def test_reflex_trips_on_any_component_and_holds_until_recovered():
    reflex = Reflex([20, 20, 20, 25, 25, 25])
    assert not reflex.check(np.array([19.0, -19, 0, 0, 0, 0]))
    assert reflex.check(np.array([0.0, 0, -20.5, 0, 0, 0])) and reflex.tripped and "fz" in reflex.reason
    assert not reflex.check(np.zeros(6)) and reflex.tripped
    assert reflex.recover() and not reflex.tripped and not reflex.recover()
    with pytest.raises(ValueError):
        Reflex([1, 2, 3])


# ------------------------------------------------- on the simulated robots
def test_each_robot_speaks_as_its_driver(sim, robot):
    emu = DriverEmulation(sim, load_profile(PROFILE_FOR[robot.package]))
    sim.step(200)
    emu.update(sim.wrench())
    rest = emu.wrench.copy()
    r_frame = sim.data.xmat[sim.model.body(emu.profile.wrench.frame_link).id].reshape(3, 3)
    sim.push([10.0, 0.0, 0.0], duration=0.5)
    sim.step(100)
    emu.update(sim.wrench())
    delta_world = r_frame @ (emu.wrench[:3] - rest[:3])
    if robot.package == "ur5_custom":
        assert np.linalg.norm(rest[:3]) < 0.05  # the tool's 9.8 N removed (payload-compensated)
        np.testing.assert_allclose(delta_world, [10.0, 0.0, 0.0], atol=0.3)
        pos, quat = emu.transforms[0]  # base -> tool0_controller: `base` is base_link turned by pi
        assert pos[0] < -0.5 and abs(abs(quat[1]) - 1.0) < 1e-3
    else:
        assert 0.5 < np.linalg.norm(rest[:3]) < 3.0 * np.sqrt(3) + 2.0  # offset + noise, no weight
        np.testing.assert_allclose(delta_world, [-10.0, 0.0, 0.0], atol=2.0)  # the reaction, noisy
        for pos, quat in emu.transforms:  # NE, EE, K at the flange
            np.testing.assert_allclose(pos, 0.0, atol=1e-9)
            np.testing.assert_allclose(np.abs(quat), [0, 0, 0, 1], atol=1e-9)


def test_emulated_controllers_refuse_commands_and_the_reflex_holds_the_arm(sim, robot):
    emu = DriverEmulation(sim, load_profile(PROFILE_FOR[robot.package]))
    if robot.package == "ur5_custom":
        assert "joint_group_vel_controller is initialized" in emu.refusal("joint_group_vel_controller")
        assert emu.switch(["joint_group_vel_controller"], ["scaled_pos_joint_traj_controller"], STRICT).ok
        assert emu.refusal("joint_group_vel_controller") == ""
        assert emu.reflex is None
        return
    assert emu.refusal("position_joint_trajectory_controller") == ""
    sim.push([0.0, 0.0, -40.0], duration=0.3)
    tripped = False
    for _ in range(50):
        sim.step(10)
        tripped = tripped or emu.update(sim.wrench())
    assert tripped and "reflex" in emu.refusal("position_joint_trajectory_controller")
    np.testing.assert_allclose(sim.position_targets, sim.qpos, atol=0.05)
    assert emu.recover() and emu.refusal("position_joint_trajectory_controller") == ""


def test_a_profile_naming_links_the_description_lacks_is_refused(sim, robot):
    other = "franka_ros" if robot.package == "ur5_custom" else "ur_robot_driver"
    with pytest.raises(ProfileError, match="not in the robot description"):
        DriverEmulation(sim, load_profile(other))


def test_profile_parameters_are_validated():
    from mujoco_driver.params import DriverParamError, DriverSettings

    settings = DriverSettings.from_params({"scene_config": "s.yaml", "profile": "franka_ros",
                                           "profile_options": {"publish_rate": 100.0}})
    assert settings.profile == "franka_ros" and settings.profile_options == {"publish_rate": 100.0}
    with pytest.raises(DriverParamError, match="~profile_options: expected a mapping"):
        DriverSettings.from_params({"scene_config": "s.yaml", "profile_options": "series: e_series"})


# ------------------------------------------------------ real sensor errors
def _rest(spec: WrenchSpec, n: int, period: float) -> np.ndarray:
    model = WrenchModel(spec, 2, period)
    zero = np.zeros(6)
    return np.array([model(zero, zero, np.zeros(2)) for _ in range(n)])


def test_white_noise_is_per_axis_and_the_drift_is_slow_with_its_time_constant():
    spec = WrenchSpec("w", "f", "l", model="payload_compensated", noise_force=[0.4, 0.6, 0.2],
                      noise_torque=0.01, seed=3)
    samples = _rest(spec, 20000, 0.002)
    np.testing.assert_allclose(samples[:, :3].std(axis=0), [0.4, 0.6, 0.2], rtol=0.05)
    # AR(1) drift, 0.3 N with tau 0.5 s at 500 Hz: adjacent samples almost equal, 0.5 s apart correlated 1/e.
    spec = WrenchSpec("w", "f", "l", model="payload_compensated", drift_force=0.3, drift_time_constant=0.5,
                      seed=4)
    drift = _rest(spec, 200000, 0.002)[:, 0]
    assert drift.std() == pytest.approx(0.3, rel=0.1)
    assert np.diff(drift).std() < 0.1 * drift.std()  # a step is 0.09 of the std: slow, not white
    lag = 250  # 0.5 s
    rho = np.corrcoef(drift[:-lag], drift[lag:])[0, 1]
    assert rho == pytest.approx(np.exp(-1.0), abs=0.1)


def test_a_heavy_press_shifts_the_zero_once_released_and_a_light_one_does_not():
    spec = WrenchSpec("w", "f", "l", model="payload_compensated", contact_shift_threshold=30.0,
                      contact_shift_fraction=0.08, seed=5)
    model = WrenchModel(spec, 1, 0.002)
    q, zero = np.zeros(1), np.zeros(6)
    press = np.array([0.0, 0.0, -116.0, 0.0, 0.0, 0.0])
    for value in (press * 0.2, zero):  # 23 N: under the threshold
        model(value, zero, q)
    np.testing.assert_allclose(model(zero, zero, q), 0.0)
    for _ in range(10):
        model(press, zero, q)
    during = model(press, zero, q)
    np.testing.assert_allclose(during, press)  # the shift comes with the release, not during the press
    after = model(zero, zero, q)
    assert np.linalg.norm(after[:3]) == pytest.approx(0.08 * 116.0, rel=1e-6)
    np.testing.assert_allclose(model(zero, zero, q), after)  # it stays
    model.zero(after)
    np.testing.assert_allclose(model(zero, zero, q), 0.0, atol=1e-12)  # zeroing removes it


def test_a_current_estimate_lags_a_step_by_its_time_constant_and_is_net_of_the_payload():
    spec = WrenchSpec("w", "f", "l", model="current_estimate", lag=0.05)
    model = WrenchModel(spec, 1, 0.008)  # a CB3's 125 Hz
    weight = np.array([0.0, 0.0, -9.81, 0.0, 0.0, 0.0])
    q = np.zeros(1)
    assert model(weight, weight, q)[2] == pytest.approx(0.0)
    step = weight + np.array([10.0, 0, 0, 0, 0, 0])
    out = [model(step, weight, q)[0] for _ in range(60)]
    # After one time constant (0.05 s = 6.25 samples) 1 - 1/e of the step; after 0.48 s all of it.
    assert out[5] < 10.0 * (1 - np.exp(-1.0)) < out[7]
    assert out[-1] == pytest.approx(10.0, rel=1e-3)


def test_the_profiles_sensor_error_keys_are_checked():
    path = os.path.join(os.path.dirname(__file__), "..", "..", "src", "mujoco_driver", "config", "profiles")
    base = yaml.safe_load(open(os.path.join(path, "ur_robot_driver.yaml")))
    for key, value, words in (("noise_force", [0.1, 0.2], "three"), ("drift_force", -1.0, ">= 0"),
                              ("model", "magic", "current_estimate"), ("lag", "x", "finite number")):
        bad = dict(base, wrench=dict(base["wrench"], **{key: value}))
        with tempfile.NamedTemporaryFile("w", suffix=".yaml", delete=False) as f:
            yaml.safe_dump(bad, f)
        with pytest.raises(ProfileError, match=words):
            load_profile(f.name)
        os.unlink(f.name)


def test_options_the_real_driver_reads_from_parameters_are_named_by_the_profile():
    assert option_params("franka_ros") == {
        "publish_rate": "franka_state_controller/publish_rate",
        "reflex_force_thresholds": "franka_control/collision_config/upper_force_thresholds_nominal",
    }
    assert option_params("ur_robot_driver") == {}
    base = yaml.safe_load(open(os.path.join(os.path.dirname(__file__), "..", "..", "src", "mujoco_driver",
                                            "config", "profiles", "franka_ros.yaml")))
    bad = dict(base, option_params={"rate": "franka_state_controller/publish_rate"})  # not an option
    with tempfile.NamedTemporaryFile("w", suffix=".yaml", delete=False) as f:
        yaml.safe_dump(bad, f)
    with pytest.raises(ProfileError, match="must be an option"):
        option_params(f.name)
    os.unlink(f.name)


def test_the_series_variants_carry_their_sensor():
    e = load_profile("ur_robot_driver", {"series": "e_series"}).wrench
    assert e.model == "payload_compensated" and e.topic == "wrench" and max(e.noise_force) > 0.1
    assert e.contact_shift_threshold > 0.0
    cb3 = load_profile("ur_robot_driver", {"series": "cb3_estimate"}).wrench
    assert cb3.model == "current_estimate" and cb3.noise_force == 3.6 and cb3.frame == "tool0_controller"
