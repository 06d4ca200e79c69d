"""A program played back in time: the reference pose and twist at each instant, pause and resume, speed
scale; and how far a measured tool position is from the recorded path (no ROS here)."""

from __future__ import annotations

import math

import numpy as np
from compliant_common.typedefs import FloatArray

from teach.program import Program
from teach.simplify import interpolate

__all__ = ["Playback", "path_distance"]


def _rotvec(q0: FloatArray, q1: FloatArray) -> FloatArray:
    """Rotation vector (fixed frame) taking orientation q0 to q1 (quaternions x, y, z, w)."""
    x0, y0, z0, w0 = q0
    x1, y1, z1, w1 = q1
    # q = q1 * conj(q0)
    w = w1 * w0 + x1 * x0 + y1 * y0 + z1 * z0
    x = -w1 * x0 + x1 * w0 - y1 * z0 + z1 * y0
    y = -w1 * y0 + y1 * w0 - z1 * x0 + x1 * z0
    z = -w1 * z0 + z1 * w0 - x1 * y0 + y1 * x0
    if w < 0.0:
        w, x, y, z = -w, -x, -y, -z
    s = math.sqrt(x * x + y * y + z * z)
    if s < 1e-12:
        return np.zeros(3)
    angle = 2.0 * math.atan2(s, w)
    return np.array([x, y, z]) * (angle / s)


class Playback:
    """The reference of a program at replay time; `advance` moves its clock (paused: it does not).

    Args:
        program: what to play.
        speed: the recorded speed times this (> 0; 2: twice as fast).
    """

    def __init__(self, program: Program, speed: float = 1.0) -> None:
        if not speed > 0.0:
            raise ValueError(f"speed must be > 0, got {speed}")
        self.program = program
        self.speed = speed
        w = program.waypoints
        self._t = np.array([p.t for p in w])
        self._p = np.array([p.position for p in w])
        self._q = np.array([p.orientation for p in w])
        self.time = 0.0  # program time [s] reached
        self.paused = False
        self.rate = 1.0  # the clock's last rate, times `speed` (< 1: slowed for the arm), scales the twist

    @property
    def duration(self) -> float:
        """Program time [s]; replay time is duration / speed."""
        return float(self._t[-1])

    @property
    def progress(self) -> float:
        return 1.0 if self.duration <= 0.0 else min(1.0, self.time / self.duration)

    @property
    def done(self) -> bool:
        return self.time >= self.duration

    def advance(self, dt: float, rate: float = 1.0) -> None:
        """`dt` [s] of replay time passed, the clock running at `rate` (in (0, 1]) times `speed`; nothing
        while paused."""
        self.rate = rate
        if not self.paused:
            self.time = min(self.duration, self.time + dt * self.speed * rate)

    def reference(
        self, lead: float = 0.0
    ) -> tuple[FloatArray, tuple[float, float, float, float], FloatArray]:
        """(position, quaternion, twist (vx, vy, vz, wx, wy, wz)) at the current time; the twist is the one
        `lead` [s] of replay time ahead (the command path's latency: the arm slows where the path does, not
        that late), zero while paused or at the end."""
        p, q, i = interpolate(self._t, self._p, self._q, self.time)
        twist = np.zeros(6)
        ahead = min(self.time + lead * self.speed * self.rate, self.duration)
        if lead > 0.0:
            i = interpolate(self._t, self._p, self._q, ahead)[2]
        if not self.paused and not self.done and ahead < self.duration:
            span = self._t[i + 1] - self._t[i]
            if span > 0.0:
                scale = self.speed * self.rate
                twist[:3] = (self._p[i + 1] - self._p[i]) / span * scale
                twist[3:] = _rotvec(self._q[i], self._q[i + 1]) / span * scale
        return p, q, twist


def path_distance(points: FloatArray, path: FloatArray) -> FloatArray:
    """Distance [m] of each point (n, 3) from the polyline `path` (m, 3): the shortest to any segment."""
    a, b = path[:-1], path[1:]
    ab = b - a
    length2 = np.maximum(np.sum(ab * ab, axis=1), 1e-18)
    out = np.empty(len(points))
    for k, x in enumerate(points):
        s = np.clip(np.sum((x - a) * ab, axis=1) / length2, 0.0, 1.0)
        out[k] = float(np.min(np.linalg.norm(a + s[:, None] * ab - x, axis=1)))
    return out
