"""The simulation core as a user (the driver node, a test pushing the tool) sees it."""

from __future__ import annotations

import dataclasses
import time

import numpy as np
import pinocchio as pin
import pytest
from mujoco_driver.sim import CommandError, Simulation, TrajectoryPoint

from mujoco_driver.config import NoiseConfig

G = 9.81


def world_wrench(sim: Simulation) -> tuple[np.ndarray, np.ndarray]:
    """The sensor's force and torque rotated to the base (world) frame."""
    rot, wrench = sim.sensor_rotation(), sim.wrench()
    return rot @ wrench[:3], rot @ wrench[3:]


def tool_weight(sim: Simulation) -> np.ndarray:
    return np.array([0.0, 0.0, -sim.scene.payload_mass * G])


def steps(sim: Simulation, seconds: float) -> None:
    sim.step(round(seconds / sim.dt))


def test_holds_still_for_two_seconds_without_warnings(sim):
    start, tip = sim.qpos, sim.eef_pose()[0]
    error = 0.0
    for _ in range(20):
        steps(sim, 0.1)
        error = max(error, np.abs(sim.qpos - start).max())
    assert sim.time == pytest.approx(2.0)
    assert error < 1e-5
    assert np.abs(sim.qvel).max() < 1e-4
    assert np.linalg.norm(sim.eef_pose()[0] - tip) < 1e-5
    assert sim.warnings() == {}


def test_sensor_at_rest_reads_the_tool_weight(robot, sim):
    steps(sim, 0.5)
    force, torque = world_wrench(sim)
    # The URDF's tool is 1 kg (description.args); the scene measures everything below the sensor.
    assert sim.scene.payload_mass == pytest.approx(1.0)
    np.testing.assert_allclose(force, tool_weight(sim), atol=0.02 * sim.scene.payload_mass * G)
    lever = sim.data.xipos[sim.scene.tool_body] - sim.data.site_xpos[sim.scene.ft_site]
    np.testing.assert_allclose(torque, np.cross(lever, tool_weight(sim)), atol=0.01)


@pytest.mark.parametrize("axis", [0, 2], ids=["x", "z"])
def test_push_shows_on_the_sensor_while_it_lasts_and_the_arm_barely_moves(sim, axis):
    steps(sim, 0.2)
    tip = sim.eef_pose()[0]
    push = np.zeros(3)
    push[axis] = 10.0
    sim.push(push, duration=0.5)
    steps(sim, 0.3)
    force, _ = world_wrench(sim)
    np.testing.assert_allclose(force - tool_weight(sim), push, atol=1.0)  # within 10% of 10 N
    assert sim.push_remaining == pytest.approx(0.2)
    assert np.linalg.norm(sim.eef_pose()[0] - tip) < 2e-3  # stiff servo: under 2 mm
    steps(sim, 0.5)
    force, _ = world_wrench(sim)
    assert sim.push_remaining == 0.0
    np.testing.assert_allclose(force, tool_weight(sim), atol=0.1)
    assert np.linalg.norm(sim.eef_pose()[0] - tip) < 1e-4


def test_push_goes_on_when_something_clears_the_applied_forces_between_steps(sim):
    """MuJoCo's passive viewer zeroes data.xfrc_applied (its mouse-perturbation channel) at every sync."""
    sim.push([10.0, 0.0, 0.0], duration=0.5)
    steps(sim, 0.1)
    for _ in range(10):  # a viewer syncing at 50 Hz
        sim.data.xfrc_applied[:] = 0.0
        steps(sim, 0.02)
    force, _ = world_wrench(sim)
    np.testing.assert_allclose(force - tool_weight(sim), [10.0, 0.0, 0.0], atol=1.0)


def test_push_torque_about_the_sensor(sim):
    sim.push([0.0, 0.0, 0.0], torque=[0.0, 0.0, 2.0], duration=1.0)
    steps(sim, 0.5)
    _, torque = world_wrench(sim)
    lever = sim.data.xipos[sim.scene.tool_body] - sim.data.site_xpos[sim.scene.ft_site]
    np.testing.assert_allclose(torque, np.array([0, 0, 2.0]) + np.cross(lever, tool_weight(sim)), atol=0.1)


@pytest.mark.parametrize("joint", [0, -1], ids=["first", "last"])
def test_velocity_command_moves_that_joint_at_that_speed(sim, joint):
    qd = np.zeros(len(sim.joint_names))
    qd[joint] = 0.2
    sim.set_velocity_targets(qd)
    steps(sim, 0.2)  # accelerate
    q1, t1 = sim.qpos, sim.time
    steps(sim, 0.5)
    speed = (sim.qpos - q1) / (sim.time - t1)
    assert speed[joint] == pytest.approx(0.2, rel=0.01)
    assert np.abs(np.delete(speed, joint % len(speed))).max() < 1e-3
    assert sim.qvel[joint] == pytest.approx(0.2, rel=0.01)
    sim.set_velocity_targets(np.zeros_like(qd))
    steps(sim, 0.3)
    assert np.abs(sim.qvel).max() < 1e-3


def test_velocity_command_is_scaled_to_the_limits(sim):
    limit = sim.scene.velocity_limit[0]
    qd = np.zeros(len(sim.joint_names))
    qd[0], qd[-1] = 4.0 * limit, 2.0 * limit  # base and tool-axis joints: nothing in the way
    sim.set_velocity_targets(qd)
    steps(sim, limit / sim.scene.max_acceleration[0] + 0.2)  # reach the speed at the acceleration limit
    # Scaled as a whole, so the direction of motion is kept.
    assert sim.qvel[0] == pytest.approx(limit, rel=0.01)
    assert sim.qvel[-1] == pytest.approx(limit / 2, rel=0.01)


def test_position_target_is_reached_within_the_velocity_limit(sim):
    goal = sim.qpos
    goal[0] += 0.5
    sim.set_position_targets(goal)
    peak = 0.0
    for _ in range(100):
        steps(sim, 0.01)
        peak = max(peak, abs(sim.qvel[0]))
    assert peak <= 1.05 * sim.scene.velocity_limit[0]
    np.testing.assert_allclose(sim.qpos, goal, atol=1e-5)


def test_position_target_is_clamped_to_the_joint_limits(sim):
    travel = sim.scene.upper - sim.qpos
    joint = int(np.argmin(travel))
    goal = sim.qpos
    goal[joint] = sim.scene.upper[joint] + 1.0
    sim.set_position_targets(goal)
    steps(sim, travel[joint] / sim.scene.velocity_limit[joint] + 1.0)
    assert sim.position_targets[joint] == sim.scene.upper[joint]


@pytest.mark.parametrize("with_velocities", [True, False])
def test_trajectory_is_tracked_and_its_end_held(sim, with_velocities):
    start = sim.qpos
    move = np.zeros_like(start)
    move[0] = move[-1] = 0.2  # base and tool-axis joints: the tool stays clear of the obstacle
    # A smooth 1 s move sampled at 0.1 s (like jog_arm's multi-point output).
    times = np.arange(1, 11) * 0.1
    shape = (1 - np.cos(np.pi * times)) / 2
    rate = np.pi * np.sin(np.pi * times) / 2
    points = [TrajectoryPoint(start + s * move, (v * move if with_velocities else None), t)
              for s, v, t in zip(shape, rate, times, strict=True)]
    sim.set_trajectory(points)
    error = 0.0
    for _ in range(60):
        steps(sim, 0.02)
        error = max(error, np.abs(sim.qpos - sim.position_targets).max())
    assert error < 1e-3
    assert sim.mode == "position"
    np.testing.assert_allclose(sim.qpos, start + move, atol=1e-4)
    assert not sim.tool_contacts()


def test_a_late_trajectory_stream_keeps_the_setpoint_acceleration_and_the_wrench_bounded(robot, sim):
    """jog_arm-like streaming (5 points every 4 ms, tip at 5 cm/s along -X) with a 40 ms hole, as when a
    loaded machine delays a message: the stream runs out, the setpoint stops and catches up, but within the
    deceleration and acceleration limits, so the sensor's inertial reading stays well below contact_control's
    25 N global limit (without the limits the hole gave 50-70 N spikes)."""
    model = robot.pin_model
    data = model.createData()
    tip = model.getFrameId(robot.cfg.links.eef)
    weight = tool_weight(sim)
    q_cmd, period = sim.qpos, 0.004
    targets, worst = [], 0.0
    for k in range(250):  # 1 s of messages
        jac = pin.computeFrameJacobian(model, data, sim.qpos, tip, pin.LOCAL_WORLD_ALIGNED)
        qd = np.linalg.lstsq(jac, [-0.05, 0, 0, 0, 0, 0], rcond=None)[0] * min(1.0, k / 25)
        q_cmd = q_cmd + qd * period
        if not 100 <= k < 110:
            sim.set_trajectory([TrajectoryPoint(q_cmd + qd * period * j, qd, period * (j + 1))
                                for j in range(5)])
        for _ in range(2):
            sim.step()
            targets.append(sim.position_targets)
            worst = max(worst, float(np.linalg.norm(world_wrench(sim)[0] - weight)))
    speed = np.diff(np.array(targets), axis=0) / sim.dt
    accel = np.diff(speed, axis=0) / sim.dt
    # A joint slowing down may brake at max_deceleration (a stop), otherwise max_acceleration.
    slowing = (speed[1:] * speed[:-1] >= 0.0) & (np.abs(speed[1:]) < np.abs(speed[:-1]))
    limit = np.where(slowing, sim.scene.max_deceleration, sim.scene.max_acceleration)
    # Within the limit, except the one step that lands exactly on a held goal (up to twice the limit).
    assert np.all(np.abs(accel) <= 2.0 * limit + 1e-6)
    assert np.mean(np.abs(accel) > limit * 1.001) < 0.01
    assert worst < 10.0
    assert sim.warnings() == {}


def test_trajectory_rejects_bad_points_and_keeps_state(sim):
    sim.set_velocity_targets(np.full(len(sim.joint_names), 0.01))
    q = sim.qpos
    bad = [
        [],
        [TrajectoryPoint(q, None, 0.2), TrajectoryPoint(q, None, 0.1)],
        [TrajectoryPoint(q[:-1], None, 0.1)],
        [TrajectoryPoint(q + np.nan, None, 0.1)],
        [TrajectoryPoint(q, [0.0], 0.1)],
        [TrajectoryPoint(q, None, float("inf"))],
        [(q, None)],
    ]
    for points in bad:
        with pytest.raises(CommandError):
            sim.set_trajectory(points)
    assert sim.mode == "velocity"


def test_bad_commands_raise_and_change_nothing(sim):
    targets = sim.position_targets
    for call, arg in [(sim.set_position_targets, [0.0]), (sim.set_velocity_targets, [np.nan] * 9),
                      (sim.set_position_targets, [np.inf] * len(sim.joint_names))]:
        with pytest.raises(CommandError):
            call(arg)
    with pytest.raises(CommandError):
        sim.push([1.0, 0.0], duration=1.0)
    with pytest.raises(CommandError):
        sim.push(["a", 0.0, 0.0], duration=1.0)
    with pytest.raises(CommandError):
        sim.set_position_targets(["x"] * len(sim.joint_names))
    with pytest.raises(CommandError):
        sim.push([1.0, 0.0, 0.0], duration=-1.0)
    assert sim.mode == "position" and sim.push_remaining == 0.0
    steps(sim, 0.1)
    np.testing.assert_allclose(sim.position_targets, targets)


def test_tool_meets_the_obstacle_when_driven_down(robot, sim):
    model = robot.pin_model
    data = model.createData()
    tip = model.getFrameId(robot.cfg.links.eef)
    down = np.array([0.0, 0.0, -0.05, 0.0, 0.0, 0.0])  # 5 cm/s, like a compliant move
    contact_time = None
    while sim.time < 3.0:
        jac = pin.computeFrameJacobian(model, data, sim.qpos, tip, pin.LOCAL_WORLD_ALIGNED)
        sim.set_velocity_targets(np.linalg.lstsq(jac, down, rcond=None)[0])
        steps(sim, 0.01)
        if contact_time is None and "obstacle" in sim.tool_contacts():
            contact_time = sim.time
        if contact_time is not None and sim.time > contact_time + 0.02:
            break
    assert contact_time is not None, "the tool never touched the obstacle"
    sim.set_velocity_targets(np.zeros(len(sim.joint_names)))
    steps(sim, 0.2)
    force, _ = world_wrench(sim)
    assert "obstacle" in sim.tool_contacts()
    assert force[2] - tool_weight(sim)[2] > 5.0  # the obstacle pushes the tool up
    top = robot.cfg.obstacle.position[2] + robot.cfg.obstacle.size[2] / 2
    assert sim.eef_pose()[0][2] == pytest.approx(top, abs=0.005)
    assert sim.warnings() == {}


def test_a_tool_pressed_on_the_block_slides_over_it_without_hopping(robot, sim):
    """Surface following's physics: the tool pressed on the block's top with 10 N (a force loop at every step,
    b = 2000 N/(m/s)) while it slides 1 cm/s along -X keeps its contact: every sample of the force within
    10 +- 1.5 N. With MuJoCo's default contact impedance it hopped at ~70 Hz (one-step dips to 2.6 N) and
    a 125 Hz driver's samples aliased that into 6-12 N means."""
    model = robot.pin_model
    data = model.createData()
    tip = model.getFrameId(robot.cfg.links.eef)
    weight = tool_weight(sim)[2]
    twist = np.zeros(6)
    touched, forces = None, []
    while sim.time < 10.0:
        force = world_wrench(sim)[0][2] - weight  # the block pushes the tool up (+Z)
        if touched is None and force > 3.0 and sim.time > 0.5:
            touched = sim.time
        twist[2] = -0.02 if touched is None else max(-0.02, (force - 10.0) / 2000.0)
        twist[0] = -0.01 if touched is not None and sim.time > touched + 1.5 else 0.0
        if touched is not None and sim.time > touched + 2.0:
            forces.append(force)
        if len(forces) >= round(1.5 / sim.dt):
            break
        jac = pin.computeFrameJacobian(model, data, sim.qpos, tip, pin.LOCAL_WORLD_ALIGNED)
        sim.set_velocity_targets(np.linalg.lstsq(jac, twist, rcond=None)[0])
        sim.step()
    assert touched is not None, "the tool never touched the block"
    forces = np.array(forces)
    assert len(forces) == round(1.5 / sim.dt), "the slide did not finish"
    assert np.mean(forces) == pytest.approx(10.0, abs=0.5)
    assert forces.min() > 8.5 and forces.max() < 11.5, (
        f"the contact force left 10 +- 1.5 N while sliding: {forces.min():.2f}..{forces.max():.2f} N, "
        f"{np.sum(np.abs(forces - 10.0) > 1.5)} of {len(forces)} samples")
    assert "obstacle" in sim.tool_contacts()
    assert sim.warnings() == {}


def test_reset_returns_to_the_start_pose(sim):
    qd = np.zeros(len(sim.joint_names))
    qd[1] = 0.3
    sim.set_velocity_targets(qd)
    sim.push([0.0, 5.0, 0.0], duration=5.0)
    steps(sim, 0.5)
    assert np.abs(sim.qpos - sim.scene.start_pose).max() > 0.05
    sim.reset()
    assert sim.time == 0.0 and sim.mode == "position" and sim.push_remaining == 0.0
    np.testing.assert_array_equal(sim.qpos, sim.scene.start_pose)
    np.testing.assert_array_equal(sim.qvel, 0.0)
    steps(sim, 0.2)
    np.testing.assert_allclose(sim.qpos, sim.scene.start_pose, atol=1e-5)
    np.testing.assert_allclose(world_wrench(sim)[0], tool_weight(sim), atol=0.1)


def test_joint_indices_map_message_order(sim):
    names = list(reversed(sim.joint_names))
    idx = sim.joint_indices(names)
    assert [sim.joint_names[i] for i in idx] == names
    with pytest.raises(CommandError, match="unknown joint"):
        sim.joint_indices(["nope"])


def test_wrench_noise_is_gaussian_and_seeded(robot):
    noisy = dataclasses.replace(robot.cfg, wrench_noise=NoiseConfig(force_std=0.5, torque_std=0.05, seed=7))
    first, second = Simulation(robot.urdf, noisy), Simulation(robot.urdf, noisy)
    samples = np.array([first.wrench() for _ in range(2000)])
    assert np.array_equal(samples[0], second.wrench())
    assert samples[:, :3].std(axis=0) == pytest.approx([0.5] * 3, rel=0.1)
    assert samples[:, 3:].std(axis=0) == pytest.approx([0.05] * 3, rel=0.1)
    out = np.empty(6)
    assert first.wrench(out) is out


def test_benchmark_steps_per_second(sim, capsys):
    """Prints how many step() + wrench() calls per second the core sustains (no timing assertion)."""
    out = np.empty(6)
    count = 2000
    begin = time.perf_counter()
    for _ in range(count):
        sim.step()
        sim.wrench(out)
    rate = count / (time.perf_counter() - begin)
    with capsys.disabled():
        print(f"\n[{sim.model.nv} joints] step()+wrench(): {rate:,.0f} steps/s "
              f"({rate * sim.dt:.1f}x real time at dt={sim.dt} s)")


def test_one_millisecond_timestep_works_too(robot):
    sim = Simulation(robot.urdf, dataclasses.replace(robot.cfg, timestep=0.001))
    steps(sim, 0.5)
    sim.push([0.0, 0.0, 10.0], duration=0.5)
    steps(sim, 0.3)
    force, _ = world_wrench(sim)
    np.testing.assert_allclose(force - tool_weight(sim), [0.0, 0.0, 10.0], atol=1.0)
    steps(sim, 0.5)
    np.testing.assert_allclose(sim.qpos, sim.scene.start_pose, atol=1e-5)
    assert sim.warnings() == {}
