"""Recorded samples -> the fewest waypoints that replay them within a tolerance (no ROS here).

Replay interpolates between waypoints linearly in time (position) and by slerp (orientation), so a sample
may be dropped when the waypoints around it predict its pose *at its time* within `position_tolerance` [m]
and `angle_tolerance` [rad]: the path and its timing both stay within the tolerance (Ramer-Douglas-Peucker
with that error). Keyframes, the first and the last sample are always kept.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Sequence

import numpy as np
from compliant_common.typedefs import FloatArray

__all__ = ["interpolate", "quaternion_angle", "simplify", "slerp"]


def quaternion_angle(a: Sequence[float], b: Sequence[float]) -> float:
    """The rotation angle between two unit quaternions (x, y, z, w) [rad]."""
    dot = abs(sum(x * y for x, y in zip(a, b, strict=True)))
    return 2.0 * math.acos(min(1.0, dot))


def slerp(a: Sequence[float], b: Sequence[float], s: float) -> tuple[float, float, float, float]:
    """Spherical interpolation from `a` (s = 0) to `b` (s = 1), the short way."""
    qa, qb = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    dot = float(qa @ qb)
    if dot < 0.0:
        qb, dot = -qb, -dot
    if dot > 0.9995:  # nearly the same: linear, normalised
        q = qa + s * (qb - qa)
    else:
        theta = math.acos(dot)
        q = (math.sin((1.0 - s) * theta) * qa + math.sin(s * theta) * qb) / math.sin(theta)
    q = q / np.linalg.norm(q)
    return (float(q[0]), float(q[1]), float(q[2]), float(q[3]))


def interpolate(times: FloatArray, positions: FloatArray, quats: FloatArray, t: float
                ) -> tuple[FloatArray, tuple[float, float, float, float], int]:
    """Position and orientation at time `t` between the samples (clamped to the ends), and the segment."""
    i = int(np.clip(np.searchsorted(times, t, side="right") - 1, 0, len(times) - 2))
    span = times[i + 1] - times[i]
    s = 0.0 if span <= 0.0 else min(1.0, max(0.0, (t - times[i]) / span))
    p = positions[i] + s * (positions[i + 1] - positions[i])
    return p, slerp(quats[i], quats[i + 1], s), i


def _slerp_many(a: FloatArray, b: FloatArray, s: FloatArray) -> FloatArray:
    """`slerp` for many s at once: (len(s), 4)."""
    dot = float(a @ b)
    if dot < 0.0:
        b, dot = -b, -dot
    if dot > 0.9995:
        q = a[None, :] + s[:, None] * (b - a)[None, :]
    else:
        theta = math.acos(dot)
        q = (np.sin((1.0 - s) * theta)[:, None] * a + np.sin(s * theta)[:, None] * b) / math.sin(theta)
    return q / np.linalg.norm(q, axis=1, keepdims=True)


def simplify(
    times: Sequence[float],
    positions: Sequence[Sequence[float]],
    quats: Sequence[Sequence[float]],
    keep: Sequence[bool] = (),
    position_tolerance: float = 0.001,
    angle_tolerance: float = math.radians(1.0),
) -> list[int]:
    """Indices of the samples to keep (sorted; always the first, the last and those marked in `keep`)."""
    n = len(times)
    if n <= 2:
        return list(range(n))
    t = np.asarray(times, dtype=float)
    p = np.asarray(positions, dtype=float)
    q = np.asarray(quats, dtype=float)
    fixed = sorted({0, n - 1} | {i for i, k in enumerate(keep) if k})
    kept = set(fixed)
    stack = list(itertools.pairwise(fixed))
    while stack:
        a, b = stack.pop()
        if b - a < 2:
            continue
        inner = np.arange(a + 1, b)
        span = t[b] - t[a]
        s = np.zeros(len(inner)) if span <= 0.0 else np.clip((t[inner] - t[a]) / span, 0.0, 1.0)
        pos_err = np.linalg.norm(p[a] + s[:, None] * (p[b] - p[a]) - p[inner], axis=1)
        dots = np.abs(np.sum(_slerp_many(q[a], q[b], s) * q[inner], axis=1))
        ang_err = 2.0 * np.arccos(np.minimum(1.0, dots))
        # Each error in units of its tolerance: the worst sample splits the segment.
        score = np.maximum(pos_err / position_tolerance, ang_err / angle_tolerance)
        worst = int(np.argmax(score))
        if score[worst] > 1.0:
            split = int(inner[worst])
            kept.add(split)
            stack.extend(((a, split), (split, b)))
    return sorted(kept)
