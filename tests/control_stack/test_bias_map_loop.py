"""A wrench whose offset changes with the pose, closed loop through the UR5 package's pipeline (no ROS): the
hybrid's 0.3 m compliant move with its 0.5 N limit stops early on the offset alone, and runs its full travel
once a bias map from a calibration sweep (control_stack.calibration) is subtracted."""

from __future__ import annotations

import numpy as np
import pytest
from contact_control.axes import LAW_COMPLIANT_MOVE, LAW_SPRING
from contact_control.bias_map import BiasMapError, MapSample, fit_bias_map, load_bias_map
from contact_control.laws import AxisLaw
from control_stack.calibration import Box, CalibrationError, plan_sweep, read_poses
from harness.pipeline_cell import Cell

G = np.array([0.0, 0.0, -9.81])
TRAVEL = 0.30  # [m] the hybrid's max path deviation along -X (ur5_custom's demos.yaml)
RNG = np.random.default_rng(21)  # its X force changes by 1.1 N over the 0.3 m travel
DIRECTIONS = RNG.normal(size=(6, 6))
DIRECTIONS *= 0.5 / np.linalg.norm(DIRECTIONS, axis=1, keepdims=True)  # 0.5 rad^-1, the emulation's scale
PHASES = RNG.uniform(0.0, 2.0 * np.pi, 6)
AMPLITUDE = np.array([3.0, 3.0, 3.0, 0.3, 0.3, 0.3])  # [N, Nm]: the "at least 3 N" for a UR
PAYLOAD_ERROR, COM_ERROR = 0.3, np.array([0.0, 0.01, 0.04])  # [kg], [m]: a wrong payload on the pendant


def sensor_error(q: np.ndarray, R: np.ndarray) -> np.ndarray:
    """A smooth offset over the joints plus a wrong payload's weight, which rotates with the tool."""
    force = PAYLOAD_ERROR * (R.T @ G)
    load = np.concatenate([force, np.cross(COM_ERROR, force)])
    return AMPLITUDE * np.sin(DIRECTIONS @ q + PHASES) + load


def hybrid(cell: Cell) -> None:
    laws = [AxisLaw() for _ in range(6)]
    laws[0] = AxisLaw(LAW_COMPLIANT_MOVE, damping=30.0, velocity=-0.05, force_limit=0.5,
                      max_travel=TRAVEL)
    laws[2] = AxisLaw(LAW_SPRING, damping=30.0, stiffness=100.0)
    cell.pipeline.contact.ctrl.set_laws(laws, None, cell.t)


def run_hybrid(cell: Cell) -> tuple[float, str]:
    """The X travel [m] of the tool tip and how the move ended."""
    for _ in range(150):  # zeroing at the start pose
        cell.step((0.0, 0.0, 0.0))
    assert cell.pipeline.contact.ctrl.last_result.safety == 0, cell.pipeline.contact.ctrl.last_result.message
    x0 = cell.pose("tool_tip")[0, 3]
    hybrid(cell)
    for _ in range(round(9.0 / 0.002)):
        cell.step((0.0, 0.0, 0.0))
        if not cell.pipeline.contact.ctrl.move_active:
            break
    return x0 - cell.pose("tool_tip")[0, 3], cell.pipeline.contact.ctrl.end_message


def calibrate(cell: Cell, path) -> str:
    """The sweep a user runs (`calibrate_bias`), done on the model: each pose's rest wrench, fitted."""
    arm = cell.pipeline.jog.jog.model
    order = [cell.names.index(n) for n in arm.joint_names]
    poses = plan_sweep(arm, cell.q[order], Box((-0.32, 0.05), (-0.05, 0.05), (-0.03, 0.08)), count=60)
    samples = []
    noise = np.random.default_rng(2)
    for q_model in poses:
        q = np.empty(len(cell.names))
        q[order] = q_model
        R = arm.frame_pose(q_model, cell.cc.ft_sensor_frame).rotation
        rest = sensor_error(q, R) + noise.normal(0.0, 0.05, 6) * [1, 1, 1, 0.01, 0.01, 0.01]
        samples.append(MapSample(tuple(q), tuple(R.T @ G), tuple(rest)))
    fitted = fit_bias_map(cell.names, samples, frame=cell.cc.ft_sensor_frame)
    print(fitted.describe())
    path.write_text(fitted.to_yaml())
    return str(path)


def test_the_offset_alone_stops_the_move_and_the_map_lets_it_run_its_travel(tmp_path) -> None:
    travel, why = run_hybrid(Cell("ur5", sensor_error=sensor_error))
    assert travel < 0.8 * TRAVEL, f"without the map it should stop early: {travel * 1e3:.1f} mm, {why}"
    assert "force" in why or "torque" in why, why
    path = calibrate(Cell("ur5"), tmp_path / "bias_map.yaml")
    mapped = Cell("ur5", params={"bias_map": path}, sensor_error=sensor_error)
    travel, why = run_hybrid(mapped)
    assert travel > TRAVEL - 0.002, f"with the map: {travel * 1e3:.1f} mm, {why}"
    assert "travel" in why or "deviation" in why, why
    # What the map leaves counts in the smallest force limit the stack accepts.
    fitted = load_bias_map(path)
    residual = mapped.pipeline.contact.ctrl.intake.pose_residual
    assert residual == (fitted.residual_force, fitted.residual_torque)


def test_a_map_of_another_frame_or_file_is_refused_before_anything_moves(tmp_path) -> None:
    path = calibrate(Cell("ur5"), tmp_path / "bias_map.yaml")
    other = tmp_path / "other.yaml"
    other.write_text(open(path).read().replace("frame: ft_sensor", "frame: tool0_controller"))
    with pytest.raises(BiasMapError, match="ft_sensor_frame is 'ft_sensor'"):
        Cell("ur5", params={"bias_map": str(other)})
    with pytest.raises(BiasMapError, match="No such file"):
        Cell("ur5", params={"bias_map": str(tmp_path / "none.yaml")})


def test_a_sweep_the_arm_cannot_reach_is_refused_with_the_reason() -> None:
    cell = Cell("ur5")
    arm = cell.pipeline.jog.jog.model
    with pytest.raises(CalibrationError, match="reachable"):
        plan_sweep(arm, cell.q, Box((2.0, 3.0), (2.0, 3.0), (2.0, 3.0)), count=10)
    with pytest.raises(CalibrationError, match="lows first"):
        Box.parse("0.1,-0.1,0,0,0,0")


def test_a_yaml_of_joint_poses_is_read_in_the_arms_order_and_checked(tmp_path) -> None:
    names = ("a", "b")
    good = tmp_path / "poses.yaml"
    good.write_text("".join(f"- {{b: {k * 0.1}, a: {-k * 0.1}, gripper: 0.0}}\n" for k in range(10)))
    poses = read_poses(str(good), names)
    assert len(poses) == 10 and np.allclose(poses[3], [-0.3, 0.3])
    bad = tmp_path / "bad.yaml"
    bad.write_text("- {a: 0.0}\n" * 10)
    with pytest.raises(CalibrationError, match=r"pose 0 has no position for \['b'\]"):
        read_poses(str(bad), names)
    short = tmp_path / "short.yaml"
    short.write_text("- {a: 0.0, b: 0.0}\n" * 3)
    with pytest.raises(CalibrationError, match="10 or more"):
        read_poses(str(short), names)


def test_a_joint_state_the_map_cannot_use_holds_the_arm_and_says_why(tmp_path) -> None:
    """The map's offset is unknown at a NaN joint position (or a short joint state): the follower's twist is
    zero, the status says why, and the next usable joint state lets the push move the arm again."""
    path = calibrate(Cell("ur5"), tmp_path / "bias_map.yaml")
    cell = Cell("ur5", params={"bias_map": path})
    for _ in range(150):  # zeroing at the start pose
        cell.step((0.0, 0.0, 0.0))
    cell.follower_z()
    p = cell.pipeline
    for bad, why in (([float("nan"), *cell.q[1:].tolist()], "a joint position is not finite"),
                     (cell.q[:3].tolist(), "3 positions for 6 joints")):
        p.on_joint_state(cell.names, bad, cell.t)
        for _ in range(50):  # 0.1 s of a 10 N push up
            cell.t += 0.002
            twist = p.on_wrench(cell.wrench((0.0, 0.0, 10.0)), cell.cc.ft_sensor_frame, cell.t, cell.t).twist
            assert twist is None or not any(twist), twist
        result = p.contact.ctrl.last_result
        assert why in result.message, result.message
    moved = [cell.step((0.0, 0.0, 10.0)) for _ in range(100)]  # usable joint states again
    assert any(t is not None and t[2] > 0.0 for t in moved)
