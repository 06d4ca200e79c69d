"""Travel of the end effector since a law was set, along and about the control axes at that moment.

Poses are 4x4 transforms of the EEF in the fixed frame; `R_fixed_control` is the control frame's orientation
in the fixed frame at the start (GCCF's "start frame"), so travel is well defined even when the control frame
moves with the robot. Rotation travel is the rotation vector of the orientation change.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

from contact_control.frames import times_transpose
from contact_control.preprocess import Matrix, as_rows

__all__ = ["MoveTravel", "TravelMeter", "rotation_vector"]

_IDENTITY = ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0))


def rotation_vector(r: Sequence[Sequence[float]]) -> tuple[float, float, float]:
    """The rotation vector (axis * angle [rad], angle in [0, pi]) of a 3x3 rotation matrix (rows)."""
    wx = r[2][1] - r[1][2]
    wy = r[0][2] - r[2][0]
    wz = r[1][0] - r[0][1]
    c = 0.5 * (r[0][0] + r[1][1] + r[2][2] - 1.0)
    s = 0.5 * math.sqrt(wx * wx + wy * wy + wz * wz)
    angle = math.atan2(s, c)
    if s > 1e-6 or c > 0.0:
        factor = 0.5 * angle / s if s > 1e-12 else 0.5
        return (wx * factor, wy * factor, wz * factor)
    # Near pi the skew part vanishes: take the axis from the diagonal, signs from the largest component.
    diag = [math.sqrt(max(0.0, (r[i][i] - c) / (1.0 - c))) for i in range(3)]
    k = max(range(3), key=lambda i: diag[i])
    axis = [0.0, 0.0, 0.0]
    axis[k] = diag[k]
    for i in range(3):
        if i != k:
            axis[i] = math.copysign(diag[i], r[k][i] + r[i][k])
    return (axis[0] * angle, axis[1] * angle, axis[2] * angle)


class TravelMeter:
    """Remembers a start pose and measures the 6-axis travel from it."""

    def __init__(self, directions: Sequence[int] = (1, 1, 1)) -> None:
        self._signs = tuple(directions) * 2
        self._p0: list[float] | None = None
        self._r0: Sequence[Sequence[float]] = _IDENTITY
        self._rc: Sequence[Sequence[float]] = _IDENTITY

    @property
    def started(self) -> bool:
        return self._p0 is not None

    def clear(self) -> None:
        self._p0 = None

    def start(self, T_fixed_eef: Matrix, R_fixed_control: Matrix | None = None) -> None:
        """Sets the start pose (4x4, fixed frame) and the control axes (3x3, fixed frame) to measure along."""
        m = as_rows(T_fixed_eef)
        self._p0 = [m[0][3], m[1][3], m[2][3]]
        self._r0 = [row[:3] for row in m[:3]]
        self._rc = _IDENTITY if R_fixed_control is None else as_rows(R_fixed_control)

    def measure(self, T_fixed_eef: Matrix, out: list[float]) -> None:
        """Writes the travel (x, y, z [m], rx, ry, rz [rad]) into `out`; zeros before `start`."""
        if self._p0 is None:
            out[:] = (0.0,) * 6
            return
        m = as_rows(T_fixed_eef)
        p0, r0, rc = self._p0, self._r0, self._rc
        dx, dy, dz = m[0][3] - p0[0], m[1][3] - p0[1], m[2][3] - p0[2]
        ax, ay, az = rotation_vector(times_transpose(m, r0))  # orientation change in the fixed frame: R R0^T
        s = self._signs
        for i in range(3):
            # Express in the start control axes: Rc^T v.
            out[i] = s[i] * (rc[0][i] * dx + rc[1][i] * dy + rc[2][i] * dz)
            out[i + 3] = s[i + 3] * (rc[0][i] * ax + rc[1][i] * ay + rc[2][i] * az)


class MoveTravel:
    """A move's travel per axis (`values`): from the pose at its start, or, for an axis whose law changed
    during the move, from the pose at the change."""

    def __init__(self, directions: Sequence[int] = (1, 1, 1)) -> None:
        self._meter = TravelMeter(directions)
        self.values = [0.0] * 6
        self._offset = [0.0] * 6  # an axis's travel when its law changed

    def restart(self, T_fixed_eef: Matrix | None, R_fixed_control: Matrix | None) -> None:
        """A new move: from `T_fixed_eef`, or from the next `measure`'s pose when None."""
        self._offset = [0.0] * 6
        self.values = [0.0] * 6
        self._meter.clear()
        if T_fixed_eef is not None:
            self._meter.start(T_fixed_eef, R_fixed_control)

    def restart_axis(self, axis: int) -> None:
        """The axis's travel counts from here."""
        self._offset[axis] += self.values[axis]
        self.values[axis] = 0.0

    def measure(self, T_fixed_eef: Matrix | None, R_fixed_control: Matrix | None) -> None:
        """Updates `values` from the pose (None: unchanged); the first pose of a move is its start."""
        if T_fixed_eef is None:
            return
        if not self._meter.started:
            self._meter.start(T_fixed_eef, R_fixed_control)
        travel = self.values
        self._meter.measure(T_fixed_eef, travel)
        offset = self._offset
        if any(offset):
            for i in range(6):
                travel[i] -= offset[i]
