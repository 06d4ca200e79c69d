"""The driver node's pure parts, no ROS: real-time pacing, the real-time factor, parameters, commands."""

from __future__ import annotations

import math
import pathlib

import numpy as np
import pytest
import yaml
from mujoco_driver.commands import trajectory_points, velocity_vector
from mujoco_driver.latency import LatencyProbe
from mujoco_driver.pacing import Pacer, RtfMeter, TrailingPublication
from mujoco_driver.params import DriverParamError, DriverSettings, load_scene, urdf_root_link
from mujoco_driver.scene import SceneError
from mujoco_driver.sim import CommandError, Simulation

from mujoco_driver.config import ConfigError

ROOT = pathlib.Path(__file__).resolve().parents[2]
NAMES = ("a", "b", "c")


def _indices(names):
    try:
        return np.array([NAMES.index(n) for n in names])
    except ValueError:
        raise CommandError(f"unknown joint in {names}") from None


# ---------------------------------------------------------------- pacing
def test_pacer_steps_on_a_fixed_grid_and_sleeps_only_when_ahead():
    pacer = Pacer(dt=0.002, real_time_factor=1.0)
    pacer.start(10.0)
    assert pacer.wait_time(10.0) == 0.0
    pacer.step_done()
    assert pacer.wait_time(10.0005) == pytest.approx(0.0015)
    # 10 ms late: the steps due at 10.002 ... 10.012 come at once (no sleeping while catching up).
    now = 10.0121
    due = 0
    while pacer.wait_time(now) == 0.0:
        pacer.step_done()
        due += 1
    assert due == 6
    assert pacer.wait_time(now) == pytest.approx(0.0019)
    assert pacer.dropped == 0.0
    assert pacer.lag(now) == 0.0


def test_pacer_lag_tells_how_far_behind_the_loop_is():
    pacer = Pacer(dt=0.002, real_time_factor=1.0)
    pacer.start(0.0)
    pacer.step_done()
    assert pacer.lag(0.001) == 0.0
    assert pacer.lag(0.0075) == pytest.approx(0.0055)
    fast = Pacer(dt=0.002, real_time_factor=0.0)
    fast.start(0.0)
    assert fast.lag(5.0) == 0.0  # as fast as possible: never behind


def test_pacer_drops_a_backlog_longer_than_max_lag():
    pacer = Pacer(dt=0.002, real_time_factor=1.0, max_lag=0.1)
    pacer.start(0.0)
    pacer.step_done()
    assert pacer.wait_time(1.0) == 0.0  # a 1 s stall: resynchronised instead of 500 catch-up steps
    assert pacer.dropped == pytest.approx(0.998)
    pacer.step_done()
    assert pacer.wait_time(1.0) == pytest.approx(0.002)


def test_a_pacer_without_catch_up_slows_the_simulation_instead_of_stepping_ahead():
    """Simulated time: a late step is due at once, the next one a full period after it (no burst, no
    skipped publication), and nothing counts as dropped."""
    pacer = Pacer(dt=0.002, real_time_factor=3.0, catch_up=False)
    pacer.start(0.0)
    pacer.step_done()
    assert pacer.wait_time(0.0105) == 0.0  # 10 ms late
    pacer.step_done()
    assert pacer.wait_time(0.0105) == pytest.approx(0.002 / 3.0)
    assert pacer.lag(0.0105) == 0.0 and pacer.dropped == 0.0
    assert pacer.lag(0.05) == 0.0  # late again, but never owed steps: the loop never skips publishing


@pytest.mark.parametrize("factor, period", [(2.0, 0.001), (0.5, 0.004), (0.0, 0.0)])
def test_pacer_period_follows_the_real_time_factor(factor, period):
    pacer = Pacer(dt=0.002, real_time_factor=factor)
    assert pacer.period == pytest.approx(period)
    pacer.start(0.0)
    pacer.step_done()
    assert (pacer.wait_time(0.0) > 0.0) == (factor > 0.0)


@pytest.mark.parametrize("kwargs", [{"dt": 0.0}, {"dt": 0.002, "real_time_factor": -1.0},
                                    {"dt": 0.002, "max_lag": 0.0}, {"dt": math.nan}])
def test_pacer_refuses_bad_settings(kwargs):
    with pytest.raises(ValueError):
        Pacer(**kwargs)


def test_rtf_meter_reports_simulated_over_wall_time_per_window_and_restarts_on_reset():
    meter = RtfMeter(period=1.0)
    assert not meter.update(0.0, 0.0)
    assert not meter.update(0.5, 0.4)
    assert meter.update(1.0, 0.9)
    assert meter.value == pytest.approx(0.9)
    assert meter.update(2.0, 2.9)
    assert meter.value == pytest.approx(2.0)
    assert not meter.update(2.5, 0.1)  # simulated time went back (reset): new window, value kept
    assert meter.value == pytest.approx(2.0)
    assert meter.update(3.5, 1.1)
    assert meter.value == pytest.approx(1.0)


def test_joint_states_go_out_half_a_period_after_the_wrench_or_before_the_next_state():
    """The driver loop's schedule at 500 Hz with joint_states_phase 0.5: the wrench at 0, its joint states at
    1 ms (the loop sleeps no further), nothing left pending; late, they go out before the next step."""
    state = TrailingPublication(0.5 * 0.002)
    assert state.armed(0.0)
    assert not state.due(0.0002) and state.sleep_time(0.0002, wait=0.0018) == pytest.approx(0.0008)
    assert state.due(0.001) and not state.due(0.0011)
    assert state.sleep_time(0.0011, wait=0.0009) == pytest.approx(0.0009)
    assert state.armed(0.002)
    assert not state.due(0.0025, state_changes=False) and state.due(0.0025, state_changes=True)
    assert not TrailingPublication(0.0).armed(0.0)  # phase 0 (or as fast as possible): at once
    with pytest.raises(ValueError):
        TrailingPublication(-1.0)


# ---------------------------------------------------------------- latency probe
def test_latency_probe_pairs_each_wrench_with_the_next_command():
    probe = LatencyProbe(horizon=0.1)
    probe.wrench_sent(1.000)
    probe.command_received(1.0003, wall=50.0)
    probe.command_received(1.0010, wall=50.1)  # a second command for the same wrench: not counted again
    probe.wrench_sent(1.002)
    probe.command_received(1.0024, wall=50.2)
    assert probe.take() == pytest.approx([50.0, 0.0003, 50.2, 0.0004])
    assert probe.take() == []


def test_latency_probe_survives_a_command_emptying_it_between_append_and_trim():
    """A command arriving in the subscriber thread right after the loop's append empties the deque; the loop
    then looked at pending[0] and died with an IndexError (the driver node with it, in a demo run)."""
    import collections

    probe = LatencyProbe(horizon=0.1)

    class Racy(collections.deque):
        def append(self, value):
            super().append(value)
            probe.command_received(value + 0.0001, wall=1.0)  # the other thread, at the worst moment

    probe._pending = Racy()
    probe.wrench_sent(1.0)
    assert probe.take() == pytest.approx([1.0, 0.0001])


def test_latency_probe_counts_a_late_command_against_every_wrench_it_was_late_for():
    probe = LatencyProbe(horizon=0.1)
    for t in (1.000, 1.002, 1.004):
        probe.wrench_sent(t)
    probe.command_received(1.0045, wall=7.0)  # errs high: 4.5, 2.5 and 0.5 ms, never the 0.5 ms alone
    assert probe.take() == pytest.approx([7.0, 0.0045, 7.0, 0.0025, 7.0, 0.0005])


def test_latency_probe_leaves_out_wrenches_nobody_answered_within_the_horizon():
    probe = LatencyProbe(horizon=0.1)
    for k in range(1000):  # two idle seconds: nothing controls the arm
        probe.wrench_sent(k * 0.002)
    probe.command_received(1.9985, wall=3.0)
    samples = probe.take()
    latencies = samples[1::2]
    assert 45 <= len(latencies) <= 51 and max(latencies) <= 0.1 and min(latencies) == pytest.approx(0.0005)
    with pytest.raises(ValueError):
        LatencyProbe(horizon=0.0)


# ---------------------------------------------------------------- params
def test_settings_defaults_and_clock_default_from_use_sim_time():
    s = DriverSettings.from_params({"scene_config": "/x/sim.yaml"})
    assert (s.real_time_factor, s.publish_clock, s.command_timeout, s.push_timeout) == (1.0, False, 0.1, 0.2)
    assert s.trajectory_command_topic == "arm_controller/command"
    assert s.velocity_command_topic == "joint_group_velocity_controller/command"
    assert s.publish_every(0.002) == 1
    assert s.joint_states_phase == 0.5
    assert DriverSettings.from_params({"scene_config": "x"}, use_sim_time=True).publish_clock
    assert DriverSettings.from_params({"scene_config": "x", "publish_period": 0.01}).publish_every(0.002) == 5


def test_faster_than_real_time_needs_the_clock():
    with pytest.raises(DriverParamError, match="real_time_factor"):
        DriverSettings.from_params({"scene_config": "x", "real_time_factor": 2.0})
    with pytest.raises(DriverParamError, match="real_time_factor"):
        DriverSettings.from_params({"scene_config": "x", "real_time_factor": 0})
    fast = DriverSettings.from_params({"scene_config": "x", "real_time_factor": 0, "publish_clock": True})
    assert fast.real_time_factor == 0.0


@pytest.mark.parametrize("params, key", [
    ({}, "scene_config"),
    ({"scene_config": "x", "scene": {"timestep": 0.002}}, "scene"),
    ({"scene_config": "x", "command_timeout": 0.0}, "command_timeout"),
    ({"scene_config": "x", "push_timeout": "long"}, "push_timeout"),
    ({"scene_config": "x", "viewer": "yes"}, "viewer"),
    ({"scene_config": "x", "publish_period": -0.1}, "publish_period"),
    ({"scene_config": "x", "joint_states_phase": 1.0}, "joint_states_phase"),
    ({"scene_config": "x", "joint_states_phase": -0.1}, "joint_states_phase"),
    ({"scene_config": "x", "wrench_topic": ""}, "wrench_topic"),
    ({"scene_config": "x", "start_pose": 1.0}, "start_pose"),
    ({"scene_config": "x", "real_time_factor": math.nan}, "real_time_factor"),
    ({"scene_config": "x", "timestep": -0.001}, "timestep"),
    ({"scene_config": "x", "timestep": 0.02}, "timestep"),
])
def test_bad_parameters_are_refused_naming_the_key(params, key):
    with pytest.raises(DriverParamError, match=key):
        DriverSettings.from_params(params)


def test_unknown_keys_refuse_start_up_naming_the_closest_valid_key():
    with pytest.raises(DriverParamError,
                       match=r"^~rtf_perod is not a parameter: did you mean ~rtf_period\?$"):
        DriverSettings.from_params({"scene_config": "x", "rtf_perod": 1.0, "viewer": False})
    with pytest.raises(DriverParamError, match="~rtf is not a parameter"):
        DriverSettings.from_params({"scene_config": "x", "rtf": 1})
    # The node reads ~robot_description itself (emulated_robot.launch sets it).
    settings = DriverSettings.from_params({"scene_config": "x", "robot_description": "<robot/>"})
    assert settings.scene_config == "x"


def test_urdf_root_link():
    urdf = ('<robot name="r"><link name="world"/><link name="base"/><link name="tip"/>'
            '<joint name="j0" type="fixed"><parent link="world"/><child link="base"/></joint>'
            '<joint name="j1" type="fixed"><parent link="base"/><child link="tip"/></joint></robot>')
    assert urdf_root_link(urdf) == "world"
    with pytest.raises(DriverParamError, match="root"):
        urdf_root_link('<robot name="r"><link name="a"/><link name="b"/></robot>')
    with pytest.raises(DriverParamError, match="XML"):
        urdf_root_link("<robot")


def test_scene_from_a_mapping_with_the_start_pose_overridden(robot):
    scene = yaml.safe_load((ROOT / "src" / robot.package / "config" / "sim.yaml").read_text())
    pose = [0.1 * (i + 1) - 0.2 for i in range(robot.pin_model.nq)]
    pose[3] = scene["start_pose"][list(scene["start_pose"])[3]]  # keep the elbow-like joints in range
    cfg = load_scene(DriverSettings.from_params({"scene": scene, "start_pose": pose}))
    sim = Simulation(robot.urdf, cfg)
    np.testing.assert_allclose(sim.qpos, pose)
    sim.step(10)
    sim.reset()
    np.testing.assert_allclose(sim.qpos, pose)  # ~reset returns to the override


def test_timestep_override_sets_the_physics_step_and_so_the_state_rate(robot):
    scene_file = str(ROOT / "src" / robot.package / "config" / "sim.yaml")
    assert load_scene(DriverSettings.from_params({"scene_config": scene_file})).timestep == 0.002  # scene's
    settings = DriverSettings.from_params({"scene_config": scene_file, "timestep": 0.001})
    sim = Simulation(robot.urdf, load_scene(settings))
    assert sim.dt == 0.001
    assert settings.publish_every(sim.dt) == 1  # the state goes out every step: 1 kHz
    sim.step(1000)
    assert sim.time == pytest.approx(1.0)


def test_bad_scene_inputs_are_refused_naming_the_key(robot, tmp_path):
    with pytest.raises(ConfigError, match="cannot read"):
        load_scene(DriverSettings.from_params({"scene_config": str(tmp_path / "missing.yaml")}))
    scene_file = ROOT / "src" / robot.package / "config" / "sim.yaml"
    cfg = load_scene(DriverSettings.from_params({"scene_config": str(scene_file),
                                                 "start_pose": {"no_such_joint": 0.0}}))
    with pytest.raises(SceneError, match="~start_pose: joints missing"):
        Simulation(robot.urdf, cfg)


# ---------------------------------------------------------------- commands
def test_velocity_vector_checks_length_and_values():
    assert velocity_vector([0.1, 0.2, 0.3], NAMES).tolist() == [0.1, 0.2, 0.3]
    with pytest.raises(CommandError, match="expected 3"):
        velocity_vector([0.1, 0.2], NAMES)
    with pytest.raises(CommandError, match="finite"):
        velocity_vector([0.1, math.nan, 0.3], NAMES)


def test_trajectory_points_reorder_and_fill_missing_joints_with_the_hold_position():
    hold = np.array([1.0, 2.0, 3.0])
    points = trajectory_points(["c", "a"], [([30.0, 10.0], [0.3, 0.1], 0.5), ([31.0, 11.0], [], 1.0)],
                               _indices, hold)
    assert points[0].positions.tolist() == [10.0, 2.0, 30.0]
    assert points[0].velocities.tolist() == [0.1, 0.0, 0.3]
    assert points[0].time_from_start == 0.5
    assert points[1].positions.tolist() == [11.0, 2.0, 31.0] and points[1].velocities is None
    assert hold.tolist() == [1.0, 2.0, 3.0]


@pytest.mark.parametrize("names, points, match", [
    ([], [([1.0], [], 1.0)], "no joint_names"),
    (["a", "a"], [([1.0, 2.0], [], 1.0)], "duplicate"),
    (["a"], [], "no points"),
    (["x"], [([1.0], [], 1.0)], "unknown"),
    (["a", "b"], [([1.0], [], 1.0)], "positions"),
    (["a", "b"], [([1.0, 2.0], [0.1], 1.0)], "velocities"),
    (["a"], [([math.inf], [], 1.0)], "finite"),
])
def test_trajectory_points_refuse_malformed_messages(names, points, match):
    with pytest.raises(CommandError, match=match):
        trajectory_points(names, points, _indices, np.zeros(3))


def test_latency_probe_survives_a_command_emptying_the_queue_during_wrench_sent():
    """The subscriber thread's command_received can pop the wrench wrench_sent has just appended (seen on a
    loaded VM: the driver died with IndexError in the middle of `make demo ROBOT=panda`)."""
    import collections

    probe = LatencyProbe(horizon=0.1)

    class Racing(collections.deque):
        def append(self, t):  # the other thread answers right after the append
            super().append(t)
            probe.command_received(t + 0.0002, wall=9.0)

    probe._pending = Racing()
    probe.wrench_sent(1.0)  # must not raise
    assert probe.take() == pytest.approx([9.0, 0.0002])
