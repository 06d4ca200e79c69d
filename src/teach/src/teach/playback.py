"""A program played back in time: the reference pose and twist at each instant, pause and resume, speed
scale; and how far a measured tool position is from the recorded path (no ROS here)."""

from __future__ import annotations

import math

import numpy as np
from compliant_common.typedefs import FloatArray

from teach.program import Program
from teach.simplify import interpolate
from teach.timing import Limits, replay_times

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
        limits: the arm's; segments that would ask more are slowed (teach.timing), none when None.
        smoothing: the fed-forward twist is the mean over this much replay time either side [s] (0: each
            segment's own, stepping at the waypoints).
    """

    def __init__(self, program: Program, speed: float = 1.0, limits: Limits | None = None,
                 smoothing: float = 0.0) -> None:
        if not speed > 0.0:
            raise ValueError(f"speed must be > 0, got {speed}")
        self.program = program
        self.speed = speed
        w = program.waypoints
        self._t = np.array([p.t for p in w])
        self._p = np.array([p.position for p in w])
        self._q = np.array([p.orientation for p in w])
        deltas = np.array([np.concatenate((self._p[i + 1] - self._p[i], _rotvec(self._q[i], self._q[i + 1])))
                           for i in range(len(w) - 1)]).reshape(-1, 6)
        self._deltas = deltas
        # The motion so far at each waypoint (position, summed rotation vectors): the fed-forward twist is its
        # central difference over 2 * smoothing, so the velocity ramps instead of stepping at a waypoint.
        self._so_far = np.vstack([np.zeros(6), np.cumsum(deltas, axis=0)])
        self.smoothing = smoothing  # [s] half the window (0: each segment's velocity, stepping at waypoints)
        # Replay time [s] at each waypoint: the program's time / speed, stretched where the arm cannot follow.
        self._r = replay_times(self._t, deltas, speed, limits or Limits())
        self.clock = 0.0  # replay time [s] reached
        self.paused = False
        self.rate = 1.0  # the clock's last rate (< 1: slowed for the arm), scales the twist

    @property
    def duration(self) -> float:
        """Program time [s] (as recorded)."""
        return float(self._t[-1])

    @property
    def planned(self) -> float:
        """Replay time [s] at the requested speed within the arm's limits (>= duration / speed)."""
        return float(self._r[-1])

    @property
    def time(self) -> float:
        """Program time [s] reached."""
        return float(np.interp(self.clock, self._r, self._t))

    @property
    def progress(self) -> float:
        return 1.0 if self.planned <= 0.0 else min(1.0, self.clock / self.planned)

    @property
    def done(self) -> bool:
        return self.clock >= self.planned

    def advance(self, dt: float, rate: float = 1.0) -> None:
        """`dt` [s] of replay time passed, the clock running at `rate` (in (0, 1]); nothing while paused."""
        self.rate = rate
        if not self.paused:
            self.clock = min(self.planned, self.clock + dt * rate)

    def reference(
        self, lead: float = 0.0
    ) -> tuple[FloatArray, tuple[float, float, float, float], FloatArray]:
        """(position, quaternion, twist (vx, vy, vz, wx, wy, wz)) at the current time; the twist is the one
        `lead` [s] of replay time ahead (the command path's latency: the arm slows where the path does, not
        that late), zero while paused or at the end."""
        p, q, _ = interpolate(self._t, self._p, self._q, self.time)
        twist = np.zeros(6)
        ahead = min(self.clock + lead * self.rate, self.planned)
        if self.paused or self.done or ahead >= self.planned:
            return p, q, twist
        h = self.smoothing
        if h > 0.0:  # from rest before the start, to rest after the end
            before, after = max(ahead - h, 0.0), min(ahead + h, self.planned)
            for k in range(6):
                column = self._so_far[:, k]
                twist[k] = (np.interp(after, self._r, column) - np.interp(before, self._r, column)) / (2 * h)
            twist *= self.rate
            return p, q, twist
        i = int(np.clip(np.searchsorted(self._r, ahead, side="right") - 1, 0, len(self._r) - 2))
        span = self._r[i + 1] - self._r[i]
        if span > 0.0:
            twist[:] = self._deltas[i] / span * self.rate
        return p, q, twist

    def horizon(self, step: float, count: int) -> list[tuple[FloatArray, tuple[float, float, float, float]]]:
        """Where the reference will be `step`, 2 `step`, ... `count` `step` [s] from now, the clock running on
        at its last rate (paused: where it is; it stops at the end): contact_control follows these when the
        stream is late."""
        ahead = 0.0 if self.paused else step * self.rate
        out = []
        for j in range(1, count + 1):
            clock = min(self.clock + j * ahead, self.planned)
            p, q, _ = interpolate(self._t, self._p, self._q, float(np.interp(clock, self._r, self._t)))
            out.append((p, q))
        return out


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
