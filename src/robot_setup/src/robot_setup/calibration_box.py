"""The box a bias-map calibration sweeps for a robot package's demonstrations (control_stack's
`calibrate_bias --box`): every tool-tip displacement the demonstrations make from the start pose, down to
`ABOVE_OBSTACLE` over the obstacle (the sweep is at rest and must not touch it)."""

from __future__ import annotations

import os

import numpy as np
from jog_arm.kinematics import ArmModel
from jog_arm.settings import held_positions
from thesis_demos.geometry import demo_motions, load_geometry, load_obstacle

from robot_setup.check import _JOG_DEFAULTS, _description, _yaml

__all__ = ["ABOVE_OBSTACLE", "demo_box"]

ABOVE_OBSTACLE = 0.02  # [m] the sweep's lowest tool tip over the obstacle's top
MARGIN = 0.01  # [m] around the demonstrations' displacements
HALF_WIDTH = 0.05  # [m] at least this far along X and Y both ways (teach's L on the block is not a motion)


def demo_box(root: str) -> str:
    """`xlow,xhigh,ylow,yhigh,zlow,zhigh` [m] of the package at `root` (tip offsets from its start pose).

    Raises:
        StackError (DemoConfigError, KinematicsError, ...), OSError: The package's files cannot be used.
    """
    cfg = os.path.join(root, "config")
    urdf, _ = _description(os.path.join(cfg, "description.args"))
    scene = _yaml(os.path.join(cfg, "sim.yaml"))
    jog = {**_JOG_DEFAULTS, **_yaml(os.path.join(cfg, "jog_arm.yaml"))}
    tip = jog.get("ee_frame_name", "tool_tip")
    held = held_positions(scene.get("held_joints") or [], "sim.yaml held_joints")
    arm = ArmModel(urdf, tip, tuple(jog.get("joint_names") or ()), held_positions=held)
    start = scene.get("start_pose") or {}
    q0 = np.array([float(start[j]) for j in arm.joint_names])
    geometry = load_geometry(os.path.join(cfg, "demos.yaml"))
    obstacle = load_obstacle(os.path.join(cfg, "sim.yaml"))
    gap = None
    if obstacle is not None:
        gap = float(arm.frame_pose(q0, tip).translation[2] - obstacle.top)
    motions = [m for per_demo in demo_motions(geometry, gap).values() for m in per_demo]
    ends = np.array([(0.0, 0.0, 0.0), *motions])
    low, high = ends.min(axis=0) - MARGIN, ends.max(axis=0) + MARGIN
    low[:2], high[:2] = np.minimum(low[:2], -HALF_WIDTH), np.maximum(high[:2], HALF_WIDTH)
    if gap is not None:
        low[2] = max(low[2], ABOVE_OBSTACLE - gap)
    return ",".join(f"{v:.3f}" for pair in zip(low, high, strict=True) for v in pair)
