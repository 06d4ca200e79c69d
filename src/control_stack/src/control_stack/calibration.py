"""The poses of a bias-map calibration sweep (pure: the robot model, no ROS; the package README's *Bias map*).

The sweep covers a box of tool positions around a start pose with the tool tilted about two axes, so the
fit can tell the load (it rotates with the tool) from an offset that follows the joints. Each pose is the
start orientation tilted by one of `TILTS` (times `tilt`) at a position of the box, solved for joint
positions by damped least squares from the previous pose (the arm stays on one branch), then ordered so
the arm goes from each pose to the nearest one left.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import pinocchio as pin
import yaml
from compliant_common.errors import StackError
from compliant_common.typedefs import FloatArray
from jog_arm.kinematics import ArmModel

__all__ = ["Box", "CalibrationError", "plan_sweep", "read_poses"]

# Tilt directions (about the base's X, Y) [x tilt]: level, both ways about each axis and four diagonals.
TILTS: tuple[tuple[float, float], ...] = (
    (0.0, 0.0), (1.0, 0.0), (-1.0, 0.0), (0.0, 1.0), (0.0, -1.0),
    (math.sqrt(0.5), math.sqrt(0.5)), (-math.sqrt(0.5), -math.sqrt(0.5)),
    (math.sqrt(0.5), -math.sqrt(0.5)), (-math.sqrt(0.5), math.sqrt(0.5)),
)
IK_TOLERANCE = 1e-4  # [m, rad] a pose's solution is this close
IK_ITERATIONS = 200
LIMIT_MARGIN = 0.05  # [rad or m] solutions keep this far from the joint limits


class CalibrationError(StackError):
    """A sweep that cannot be planned (no reachable pose, a bad box)."""


@dataclass(frozen=True)
class Box:
    """Tool tip offsets from the start pose, base axes [m]: (low, high) per axis."""

    x: tuple[float, float] = (-0.1, 0.1)
    y: tuple[float, float] = (-0.1, 0.1)
    z: tuple[float, float] = (-0.05, 0.1)

    @classmethod
    def parse(cls, text: str) -> Box:
        """From "xlow,xhigh,ylow,yhigh,zlow,zhigh" [m].

        Raises:
            CalibrationError: Not 6 numbers, or a low above its high.
        """
        try:
            v = [float(p) for p in text.split(",")]
        except ValueError as err:
            raise CalibrationError(f"box {text!r}: {err}") from err
        if len(v) != 6 or any(lo > hi for lo, hi in zip(v[::2], v[1::2], strict=True)):
            raise CalibrationError(f"box {text!r}: expected xlow,xhigh,ylow,yhigh,zlow,zhigh [m], lows first")
        return cls((v[0], v[1]), (v[2], v[3]), (v[4], v[5]))

    def points(self, per_axis: int) -> list[FloatArray]:
        axes = [np.linspace(lo, hi, per_axis) for lo, hi in (self.x, self.y, self.z)]
        return [np.array([a, b, c]) for a in axes[0] for b in axes[1] for c in axes[2]]


def _rotation(rx: float, ry: float) -> FloatArray:
    vector = np.array([rx, ry, 0.0])
    out: FloatArray = pin.exp3(vector)
    return out


def _solve(arm: ArmModel, q0: FloatArray, target: pin.SE3) -> FloatArray | None:
    """Joint positions that put the tip at `target`, from `q0`; None if out of reach or the limits."""
    q = q0.copy()
    lower, upper = arm.lower + LIMIT_MARGIN, arm.upper - LIMIT_MARGIN
    for _ in range(IK_ITERATIONS):
        J = arm.jacobian(q)
        tip = arm.data.oMf[arm.tip_id]
        turn = pin.log3(target.rotation @ tip.rotation.T)
        error = np.concatenate([target.translation - tip.translation, turn])
        if np.max(np.abs(error)) < IK_TOLERANCE:
            return q if np.all(q >= lower) and np.all(q <= upper) else None
        step = J.T @ np.linalg.solve(J @ J.T + 1e-4 * np.eye(6), error)
        q = np.clip(q + step, lower, upper)
    return None


def plan_sweep(arm: ArmModel, q_start: Sequence[float], box: Box, tilt: float = 0.3, count: int = 40,
               seed: int = 0) -> list[FloatArray]:
    """Joint positions (model order) of `count` poses at rest; see the module docstring.

    Raises:
        CalibrationError: Fewer than `count` reachable poses in the box.
    """
    if count < 10:
        raise CalibrationError(f"a sweep needs 10 or more poses, got {count}")
    q0 = np.asarray(q_start, dtype=float)
    arm.jacobian(q0)
    start = arm.data.oMf[arm.tip_id].copy()
    rng = np.random.default_rng(seed)
    candidates = [(p, t) for p in box.points(3) for t in TILTS]
    rng.shuffle(candidates)
    poses: list[FloatArray] = []
    for offset, (tx, ty) in candidates:
        target = pin.SE3(_rotation(tilt * tx, tilt * ty) @ start.rotation, start.translation + offset)
        q = _solve(arm, q0, target)
        if q is not None:
            poses.append(q)
        if len(poses) == count:
            break
    if len(poses) < count:
        raise CalibrationError(f"only {len(poses)} of {count} poses of the box are reachable within the "
                               "joint limits: give a smaller box or tilt")
    return _nearest_first(q0, poses)


def _nearest_first(q0: FloatArray, poses: list[FloatArray]) -> list[FloatArray]:
    ordered, left, at = [], list(poses), q0
    while left:
        k = int(np.argmin([np.max(np.abs(p - at)) for p in left]))
        at = left.pop(k)
        ordered.append(at)
    return ordered


def read_poses(path: str, joint_names: Sequence[str]) -> list[FloatArray]:
    """Joint poses from a YAML list of {joint: position} (every arm joint in each), in `joint_names` order.

    Raises:
        CalibrationError: Unreadable, not a list of mappings, a joint missing (named), or fewer than 10.
    """
    try:
        with open(path) as handle:
            doc = yaml.safe_load(handle)
    except (OSError, yaml.YAMLError) as err:
        raise CalibrationError(f"poses {path}: {err}") from err
    if not isinstance(doc, list) or not all(isinstance(p, dict) for p in doc):
        raise CalibrationError(f"poses {path}: expected a list of {{joint: position}} mappings")
    poses = []
    for k, pose in enumerate(doc):
        missing = [n for n in joint_names if n not in pose]
        if missing:
            raise CalibrationError(f"poses {path}: pose {k} has no position for {missing}")
        poses.append(np.array([float(pose[n]) for n in joint_names]))
    if len(poses) < 10:
        raise CalibrationError(f"poses {path}: a sweep needs 10 or more poses, got {len(poses)}")
    return poses
