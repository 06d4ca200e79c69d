"""A path of tool poses run at a set speed: where its reference is t seconds in, and how far a tool is from it
(no ROS here).

Positions are joined by straight segments, orientations by slerp; a segment takes its length at `speed`, or
longer if it turns faster than `angular_speed`. The run speeds up over its first `ramp` seconds and slows
down over its last (a step in speed on a part with friction makes the tool stick, then jam). The poses are
the tool tip's (contact_control's eef_frame) in its fixed frame, with z along the tool's axis into the part;
see the package README, *Paths at a force*.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from compliant_common.typedefs import FloatArray
from contact_control.frames import quaternion_matrix, times_transpose
from contact_control.travel import rotation_vector

from contact_tasks.task import TaskError

__all__ = ["PathPoint", "PosePath", "quaternion_slerp"]


@dataclass(frozen=True)
class PathPoint:
    """The path `t` seconds in: position [m], quaternion (x, y, z, w), twist (m/s, rad/s), whether it ended,
    the distance run along it [m] and the segment it is on."""

    position: tuple[float, float, float]
    quaternion: tuple[float, float, float, float]
    twist: tuple[float, float, float, float, float, float]
    done: bool
    arc: float
    segment: int


def quaternion_slerp(a: FloatArray, b: FloatArray, u: float) -> FloatArray:
    """The rotation `u` (0..1) of the way from unit quaternion `a` to `b` (x, y, z, w), the short way."""
    dot = float(a @ b)
    if dot < 0.0:
        b, dot = -b, -dot
    if dot > 0.9995:  # nearly the same: linear, normalised
        q = a + u * (b - a)
        return q / np.linalg.norm(q)
    theta = math.acos(dot)
    return (math.sin((1.0 - u) * theta) * a + math.sin(u * theta) * b) / math.sin(theta)


def _turn(a: FloatArray, b: FloatArray) -> FloatArray:
    """The rotation vector (fixed frame) that turns orientation `a` into `b` (quaternions): R_b R_a^T."""
    return np.asarray(rotation_vector(times_transpose(quaternion_matrix(*b), quaternion_matrix(*a))))


class PosePath:
    """`poses`: N >= 2 rows (x, y, z, qx, qy, qz, qw); `speed` [m/s]; `angular_speed` [rad/s] bounds the turn;
    `ramp` [s]: the time to speed up at the start and to slow down at the end (constant acceleration).

    Raises:
        TaskError: fewer than two poses, a row that is not seven finite numbers, a zero quaternion, a
            segment that neither moves nor turns, or a speed that is not positive.
    """

    def __init__(self, poses: Sequence[Sequence[float]], speed: float, angular_speed: float = 0.2,
                 ramp: float = 0.0) -> None:
        try:
            rows = np.asarray(poses, dtype=float)
        except (TypeError, ValueError):
            rows = np.zeros((0,))
        if rows.ndim != 2 or rows.shape[1] != 7 or len(rows) < 2:
            raise TaskError("a path needs at least two poses of 7 numbers each (x y z qx qy qz qw)")
        if not np.all(np.isfinite(rows)):
            raise TaskError("a path pose is not finite")
        norms = np.linalg.norm(rows[:, 3:], axis=1)
        if np.any(norms < 1e-9):
            raise TaskError(f"path pose {int(np.argmin(norms))}: its quaternion is zero")
        if not (speed > 0.0 and angular_speed > 0.0):
            raise TaskError(f"a path's speed must be positive, got {speed:g} m/s, {angular_speed:g} rad/s")
        self.positions = rows[:, :3].copy()
        quats = rows[:, 3:] / norms[:, None]
        for i in range(1, len(quats)):  # the short way between neighbours
            if quats[i] @ quats[i - 1] < 0.0:
                quats[i] = -quats[i]
        self.quaternions = quats
        self.lengths = np.linalg.norm(np.diff(self.positions, axis=0), axis=1)
        spins = [_turn(quats[i], quats[i + 1]) for i in range(len(quats) - 1)]
        turns = np.array([float(np.linalg.norm(w)) for w in spins])
        still = np.flatnonzero((self.lengths < 1e-9) & (turns < 1e-9))
        if still.size:
            raise TaskError(f"path poses {int(still[0])} and {int(still[0]) + 1} are the same")
        self.durations = np.maximum(self.lengths / speed, turns / angular_speed)
        self.starts = np.concatenate([[0.0], np.cumsum(self.durations)])
        self.arcs = np.concatenate([[0.0], np.cumsum(self.lengths)])
        self.length = float(self.arcs[-1])
        self._nominal = float(self.starts[-1])  # at full speed throughout
        self.ramp = min(max(ramp, 0.0), self._nominal)
        self.duration = self._nominal + self.ramp
        self._spin = [w / d for w, d in zip(spins, self.durations, strict=True)]

    @property
    def segments(self) -> int:
        return len(self.lengths)

    def _warp(self, t: float) -> tuple[float, float]:
        """The time at full speed that `t` [s] of the ramped run has reached, and the speed's fraction."""
        r, end = self.ramp, self.duration
        if r <= 0.0:
            return t, 1.0
        if t < r:
            return t * t / (2.0 * r), t / r
        if t > end - r:
            left = end - t
            return self._nominal - left * left / (2.0 * r), left / r
        return t - r / 2.0, 1.0

    def at(self, t: float) -> PathPoint:
        """The reference `t` seconds [s] after the path began (before: its start; after: its end, still)."""
        if t >= self.duration:
            p, q = self.positions[-1], self.quaternions[-1]
            return PathPoint(_xyz(p), _xyzw(q), (0.0,) * 6, True, self.length, self.segments - 1)
        t, fraction = self._warp(max(t, 0.0))
        t = min(t, self._nominal * (1.0 - 1e-12))
        i = int(np.searchsorted(self.starts, t, side="right")) - 1
        u = (t - self.starts[i]) / self.durations[i]
        p = self.positions[i] + u * (self.positions[i + 1] - self.positions[i])
        q = quaternion_slerp(self.quaternions[i], self.quaternions[i + 1], u)
        v = (self.positions[i + 1] - self.positions[i]) * (fraction / self.durations[i])
        w = self._spin[i] * fraction
        twist = (float(v[0]), float(v[1]), float(v[2]), float(w[0]), float(w[1]), float(w[2]))
        return PathPoint(_xyz(p), _xyzw(q), twist, False, float(self.arcs[i] + u * self.lengths[i]), i)

    def nearest(self, position: Sequence[float]) -> tuple[float, FloatArray, int]:
        """The arc length [m] of the path's point nearest to `position`, the offset from it (position minus
        that point) and its segment."""
        x = np.asarray(position, dtype=float)
        best = (math.inf, 0.0, np.zeros(3), 0)
        for i in range(self.segments):
            a, d, n = self.positions[i], self.positions[i + 1] - self.positions[i], self.lengths[i]
            u = 0.0 if n < 1e-12 else min(1.0, max(0.0, float((x - a) @ d) / (n * n)))
            off = x - (a + u * d)
            dist = float(off @ off)
            if dist < best[0]:
                best = (dist, float(self.arcs[i] + u * n), off, i)
        return best[1], best[2], best[3]

    def tangent(self, segment: int) -> FloatArray:
        """The unit direction of `segment` (zeros for a turn in place)."""
        n = self.lengths[segment]
        d = self.positions[segment + 1] - self.positions[segment]
        return d / n if n > 1e-12 else np.zeros(3)


def _xyz(p: FloatArray) -> tuple[float, float, float]:
    return (float(p[0]), float(p[1]), float(p[2]))


def _xyzw(q: FloatArray) -> tuple[float, float, float, float]:
    return (float(q[0]), float(q[1]), float(q[2]), float(q[3]))
