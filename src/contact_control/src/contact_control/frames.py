"""Small rigid-transform helpers on nested row lists (4x4 / 3x3), for turning tf lookups into library inputs.

Plain floats: the node composes at most a few per cycle, and numpy's per-call overhead would dominate.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

__all__ = [
    "IDENTITY",
    "compose",
    "inverse",
    "matrix_quaternion",
    "quaternion_matrix",
    "rotate_twist",
    "rotation",
    "rotation_angle",
    "times_transpose",
    "transform",
    "transpose_times",
]

Rows = list[list[float]]

IDENTITY: Rows = [[1.0, 0.0, 0.0, 0.0], [0.0, 1.0, 0.0, 0.0], [0.0, 0.0, 1.0, 0.0], [0.0, 0.0, 0.0, 1.0]]


def quaternion_matrix(x: float, y: float, z: float, w: float) -> Rows:
    """3x3 rotation of a unit quaternion (normalised here, as tf messages may carry rounding)."""
    n = (x * x + y * y + z * z + w * w) ** 0.5
    x, y, z, w = x / n, y / n, z / n, w / n
    return [
        [1.0 - 2.0 * (y * y + z * z), 2.0 * (x * y - z * w), 2.0 * (x * z + y * w)],
        [2.0 * (x * y + z * w), 1.0 - 2.0 * (x * x + z * z), 2.0 * (y * z - x * w)],
        [2.0 * (x * z - y * w), 2.0 * (y * z + x * w), 1.0 - 2.0 * (x * x + y * y)],
    ]


def matrix_quaternion(r: Sequence[Sequence[float]]) -> tuple[float, float, float, float]:
    """The unit quaternion (x, y, z, w) of a rotation (3x3 or 4x4 rows), w >= 0 (Shepperd's method: the
    largest of the four diagonal sums is the divisor)."""
    trace = r[0][0] + r[1][1] + r[2][2]
    if trace > 0.0:
        s = 2.0 * (trace + 1.0) ** 0.5
        q = ((r[2][1] - r[1][2]) / s, (r[0][2] - r[2][0]) / s, (r[1][0] - r[0][1]) / s, 0.25 * s)
    elif r[0][0] > r[1][1] and r[0][0] > r[2][2]:
        s = 2.0 * (1.0 + r[0][0] - r[1][1] - r[2][2]) ** 0.5
        q = (0.25 * s, (r[0][1] + r[1][0]) / s, (r[0][2] + r[2][0]) / s, (r[2][1] - r[1][2]) / s)
    elif r[1][1] > r[2][2]:
        s = 2.0 * (1.0 + r[1][1] - r[0][0] - r[2][2]) ** 0.5
        q = ((r[0][1] + r[1][0]) / s, 0.25 * s, (r[1][2] + r[2][1]) / s, (r[0][2] - r[2][0]) / s)
    else:
        s = 2.0 * (1.0 + r[2][2] - r[0][0] - r[1][1]) ** 0.5
        q = ((r[0][2] + r[2][0]) / s, (r[1][2] + r[2][1]) / s, 0.25 * s, (r[1][0] - r[0][1]) / s)
    n = (q[0] ** 2 + q[1] ** 2 + q[2] ** 2 + q[3] ** 2) ** 0.5 * (1.0 if q[3] >= 0.0 else -1.0)
    return (q[0] / n, q[1] / n, q[2] / n, q[3] / n)


def transform(translation: Sequence[float], quaternion: Sequence[float]) -> Rows:
    """4x4 from a translation (x, y, z) and a quaternion (x, y, z, w)."""
    r = quaternion_matrix(*quaternion)
    return [r[0] + [translation[0]], r[1] + [translation[1]], r[2] + [translation[2]], [0.0, 0.0, 0.0, 1.0]]


def rotation_angle(a: Sequence[Sequence[float]], b: Sequence[Sequence[float]]) -> float:
    """Angle [rad] of the rotation between two rotation matrices (3x3 rows)."""
    trace = sum(a[0][i] * b[0][i] + a[1][i] * b[1][i] + a[2][i] * b[2][i] for i in range(3))
    return math.acos(max(-1.0, min(1.0, (trace - 1.0) / 2.0)))


def rotation(t: Sequence[Sequence[float]]) -> Rows:
    """The 3x3 rotation block of a 4x4."""
    return [list(t[0][:3]), list(t[1][:3]), list(t[2][:3])]


def compose(a: Sequence[Sequence[float]], b: Sequence[Sequence[float]]) -> Rows:
    """a * b for 4x4 rigid transforms."""
    out = [[0.0, 0.0, 0.0, 0.0] for _ in range(3)] + [[0.0, 0.0, 0.0, 1.0]]
    for i in range(3):
        ai = a[i]
        for j in range(4):
            out[i][j] = ai[0] * b[0][j] + ai[1] * b[1][j] + ai[2] * b[2][j] + (ai[3] if j == 3 else 0.0)
    return out


def inverse(t: Sequence[Sequence[float]]) -> Rows:
    """Inverse of a 4x4 rigid transform: (R^T, -R^T p)."""
    px, py, pz = t[0][3], t[1][3], t[2][3]
    out = []
    for i in range(3):
        r0, r1, r2 = t[0][i], t[1][i], t[2][i]
        out.append([r0, r1, r2, -(r0 * px + r1 * py + r2 * pz)])
    out.append([0.0, 0.0, 0.0, 1.0])
    return out


def transpose_times(a: Sequence[Sequence[float]], b: Sequence[Sequence[float]]) -> Rows:
    """a^T b for 3x3 rotations (e.g. R_command_control = R_fixed_command^T R_fixed_control)."""
    return [[a[0][i] * b[0][j] + a[1][i] * b[1][j] + a[2][i] * b[2][j] for j in range(3)] for i in range(3)]


def times_transpose(a: Sequence[Sequence[float]], b: Sequence[Sequence[float]]) -> Rows:
    """a b^T for 3x3 rotations (or the rotation blocks of 4x4s): the turn from b to a, in their frame."""
    return [[a[i][0] * b[j][0] + a[i][1] * b[j][1] + a[i][2] * b[j][2] for j in range(3)] for i in range(3)]


def rotate_twist(r: Sequence[Sequence[float]], v: Sequence[float]) -> list[float]:
    """Both halves of a twist rotated by r (a change of frame orientation, same reference point)."""
    out = [0.0] * 6
    for k in (0, 3):
        x, y, z = v[k], v[k + 1], v[k + 2]
        for i in range(3):
            out[k + i] = r[i][0] * x + r[i][1] * y + r[i][2] * z
    return out
