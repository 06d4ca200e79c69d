"""Paths planned on a part's nominal model, and where the real part is (pure geometry, no ROS).

The curved demonstration plans the tool tip's path over a cylinder whose axis is parallel to the base's y
(mujoco_driver's `cylinder` fixture): the tool's axis (its z) along the inward normal, its other axes turned
from the start pose's about y. The truth (`~surface` of the simulated driver) gives the real normal for
judging.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np
from compliant_common.typedefs import FloatArray
from contact_control.frames import matrix_quaternion

__all__ = ["cylinder_normal", "cylinder_path", "turn_about_y"]


def turn_about_y(angle: float) -> FloatArray:
    c, s = math.cos(angle), math.sin(angle)
    return np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])


def cylinder_path(top: Sequence[float], radius: float, length: float, tool: FloatArray,
                  step: float = 0.01, middle: float = 0.0) -> list[list[float]]:
    """Poses (x, y, z, qx, qy, qz, qw) every `step` [m] along an arc of `length` [m] over a cylinder whose
    highest point is `top` (its axis along y), from -x to +x, its middle `middle` [rad] from the top (+: on
    the +x side); the tool's orientation is the 3x3 `tool` (pointing down at the top) turned about y with
    the surface."""
    half = length / (2.0 * radius)
    count = max(2, round(length / step) + 1)
    centre = np.asarray(top, dtype=float) - (0.0, 0.0, radius)
    poses = []
    for a in np.linspace(middle - half, middle + half, count):
        p = centre + radius * np.array([math.sin(a), 0.0, math.cos(a)])
        R = turn_about_y(a) @ tool
        poses.append([*(float(x) for x in p), *matrix_quaternion(R.tolist())])
    return poses


def cylinder_normal(top: Sequence[float], radius: float, point: Sequence[float]) -> FloatArray:
    """The outward unit normal of the cylinder (axis along y, highest point `top`) nearest `point`."""
    out = np.asarray(point, dtype=float) - np.asarray(top, dtype=float) + (0.0, 0.0, radius)
    out[1] = 0.0
    return out / np.linalg.norm(out)
