"""The scene as data: MuJoCo and Pinocchio agree on the URDF, and the start pose suits the demos."""

from __future__ import annotations

import dataclasses

import mujoco
import numpy as np
import pinocchio as pin
import pytest
from mujoco_driver.scene import SceneError, build_scene, mujoco_urdf, rpy_to_quat

from mujoco_driver.config import LinkNames

# jog_arm halts at a Jacobian condition number of 12 (spec: hard_stop_singularity_threshold).
HARD_STOP_CONDITION = 12.0


def _condition(model: pin.Model, data: pin.Data, q: np.ndarray, frame: int) -> float:
    jac = pin.computeFrameJacobian(model, data, q, frame, pin.LOCAL_WORLD_ALIGNED)
    sv = np.linalg.svd(jac, compute_uv=False)
    return float(sv[0] / sv[-1])


def _move_tip(model, data, q, frame, offset, steps=30):
    """Resolved-rate motion of the tip by ``offset`` (orientation held), as jog_arm would do it.

    Returns the joint path and the condition numbers along it.
    """
    pin.framesForwardKinematics(model, data, q)
    start = data.oMf[frame].copy()
    path, conds = [], []
    for k in range(1, steps + 1):
        goal = pin.SE3(start.rotation, start.translation + np.asarray(offset) * k / steps)
        for _ in range(20):
            pin.framesForwardKinematics(model, data, q)
            err = pin.log6(data.oMf[frame].actInv(goal)).vector
            if np.linalg.norm(err) < 1e-9:
                break
            jac = pin.computeFrameJacobian(model, data, q, frame, pin.LOCAL)
            q = q + jac.T @ np.linalg.solve(jac @ jac.T + 1e-9 * np.eye(6), err)
        assert np.linalg.norm(err) < 1e-6, f"tip cannot reach {goal.translation}"
        path.append(q.copy())
        conds.append(_condition(model, data, q, frame))
    return np.array(path), conds


def test_joint_names_order_and_limits_agree(robot, shared_sim):
    model, scene = robot.pin_model, shared_sim.scene
    assert list(model.names)[1:] == list(shared_sim.joint_names)
    assert len(shared_sim.joint_names) in (6, 7)
    np.testing.assert_allclose(model.lowerPositionLimit, scene.lower)
    np.testing.assert_allclose(model.upperPositionLimit, scene.upper)
    np.testing.assert_allclose(model.velocityLimit, scene.velocity_limit)
    jnt = [shared_sim.model.joint(n).id for n in shared_sim.joint_names]
    np.testing.assert_allclose(model.effortLimit, shared_sim.model.jnt_actfrcrange[jnt, 1])
    np.testing.assert_allclose(-model.effortLimit, shared_sim.model.jnt_actfrcrange[jnt, 0])


def test_forward_kinematics_agree_for_every_link(robot, sim):
    model = robot.pin_model
    data = model.createData()
    pin.framesForwardKinematics(model, data, sim.qpos)
    compared = 0
    for body in range(1, sim.model.nbody):
        name = sim.model.body(body).name
        if not model.existFrame(name):
            continue
        frame = data.oMf[model.getFrameId(name)]
        np.testing.assert_allclose(sim.data.xpos[body], frame.translation, atol=1e-9, err_msg=name)
        np.testing.assert_allclose(sim.data.xmat[body].reshape(3, 3), frame.rotation, atol=1e-9, err_msg=name)
        compared += 1
    assert compared >= len(sim.joint_names) + 3
    position, quat_xyzw = sim.eef_pose()
    tip = data.oMf[model.getFrameId(robot.cfg.links.eef)]
    np.testing.assert_allclose(position, tip.translation, atol=1e-9)
    rot = np.zeros(9)
    mujoco.mju_quat2Mat(rot, np.roll(quat_xyzw, 1))  # eef_pose gives x, y, z, w; MuJoCo wants w first
    np.testing.assert_allclose(rot.reshape(3, 3), tip.rotation, atol=1e-9)


def test_start_pose_is_well_conditioned_and_tool_points_down(robot, shared_sim):
    model = robot.pin_model
    data = model.createData()
    q = shared_sim.scene.start_pose
    tip = model.getFrameId(robot.cfg.links.eef)
    pin.framesForwardKinematics(model, data, q)
    assert _condition(model, data, q, tip) < 10.0
    assert data.oMf[tip].rotation[:, 2] @ [0, 0, -1] > 0.999
    margin = np.minimum(q - model.lowerPositionLimit, model.upperPositionLimit - q)
    assert margin.min() > 0.3


def test_obstacle_sits_5_to_10_cm_below_the_tool(robot, sim):
    obstacle = robot.cfg.obstacle
    assert obstacle is not None
    tip, _ = sim.eef_pose()
    rot = np.zeros(9)
    mujoco.mju_quat2Mat(rot, rpy_to_quat(obstacle.rpy))
    local = rot.reshape(3, 3).T @ (tip - np.array(obstacle.position))
    half = np.array(obstacle.size) / 2
    assert np.all(np.abs(local[:2]) < half[:2] - 0.03), "tool tip not above the obstacle"
    gap = local[2] - half[2]
    assert 0.05 <= gap <= 0.10
    assert not sim.tool_contacts() and sim.data.ncon == 0


@pytest.mark.parametrize(
    "offset",
    [(-0.30, 0.0, 0.0), (0.05, 0.0, 0.0), (0.0, 0.0, 0.05), (0.0, 0.0, -0.05),
     (0.0, 0.05, 0.0), (0.0, -0.05, 0.0)],
    ids=["x-0.30", "x+0.05", "z+0.05", "z-0.05", "y+0.05", "y-0.05"],
)
def test_demo_motions_stay_clear_of_limits_and_singularities(robot, shared_sim, offset):
    """The hybrid demo's 0.30 m along -X, and spring/follower pushes of a few cm, from the start pose."""
    model = robot.pin_model
    path, conds = _move_tip(model, model.createData(), shared_sim.scene.start_pose.copy(),
                            model.getFrameId(robot.cfg.links.eef), offset)
    assert max(conds) < HARD_STOP_CONDITION - 2.0
    margin = np.minimum(path - model.lowerPositionLimit, model.upperPositionLimit - path)
    assert margin.min() > 0.2


def test_tool_is_not_gravity_compensated_but_arm_is(shared_sim):
    model, scene = shared_sim.model, shared_sim.scene
    assert model.body_gravcomp[scene.tool_body] == 0.0
    assert scene.payload_mass > 0.5
    arm = [model.jnt_bodyid[model.joint(n).id] for n in shared_sim.joint_names]
    assert np.all(model.body_gravcomp[arm] == 1.0)


def test_visual_meshes_dropped_and_fixed_links_kept(robot, shared_sim):
    assert ".dae" not in mujoco_urdf(robot.urdf)
    names = {shared_sim.model.body(i).name for i in range(shared_sim.model.nbody)}
    assert {"ft_sensor", "tool", "tool_tip"} <= names


@pytest.mark.parametrize("role", ["ft_sensor", "tool", "eef"])
def test_missing_links_are_refused(robot, role):
    cfg = dataclasses.replace(robot.cfg, links=dataclasses.replace(LinkNames(), **{role: "no_such_link"}))
    with pytest.raises(SceneError, match=f"links.{role}"):
        build_scene(robot.urdf, cfg)


def test_start_pose_outside_limits_is_refused(robot, shared_sim):
    bad = dict(zip(shared_sim.joint_names, shared_sim.scene.upper + 1.0, strict=True))
    cfg = dataclasses.replace(robot.cfg, start_pose=dataclasses.replace(robot.cfg.start_pose, value=bad))
    with pytest.raises(SceneError, match="outside their limits"):
        build_scene(robot.urdf, cfg)


def test_unresolved_mesh_uri_is_refused(robot):
    with pytest.raises(SceneError, match="absolute"):
        build_scene(robot.urdf.replace("file://", "package://x"), robot.cfg)
