"""The moving reference of the path law (LAW_PATH): a pose and a twist in the fixed frame, streamed by a
replay.

V = v_ref + k e (+ F / b): `PathReference.error` gives, per control axis, the pose error e (reference minus
end effector: position [m], rotation vector [rad]) and v_ref, both along the control axes. The reference is
held for `timeout` after its stamp: for `extrapolate` s its position moves on with its velocity; then, if it
came with a horizon (where it will be every `step` s after), it follows the horizon to its end, and then it
stands still (no velocity fed forward); an older one is lost, and the move ends (the replay stopped
sending). A move that starts before its stream's first reference has arrived (the sender's topic connects a
moment after its first message, or the message is still on its way behind the ConfigureLaws call) stands
still for up to `timeout` waiting for it. A horizon lets a late sender (a stalled replay) keep the tool on
its path instead of stopping it (teach's README, *Replay*). No ROS here.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

from contact_control.axes import End
from contact_control.frames import quaternion_matrix, times_transpose
from contact_control.law_set import LawSet
from contact_control.preprocess import Matrix, as_rows
from contact_control.travel import rotation_vector

__all__ = ["PathReference"]

_IDENTITY = ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0))


class PathReference:
    """The latest reference; see the module docstring.

    Args:
        timeout: a reference older than this [s] is lost.
        extrapolate: its position moves on with its velocity for at most this long [s].
    """

    def __init__(self, timeout: float, extrapolate: float) -> None:
        self.timeout = timeout
        self.extrapolate = extrapolate
        self._t: float | None = None
        self._p = (0.0, 0.0, 0.0)
        self._r: list[list[float]] = [list(row) for row in _IDENTITY]
        self._v = (0.0,) * 6
        self._step = 0.0
        self._ahead: list[tuple[tuple[float, ...], tuple[float, ...]]] = []  # (position, quaternion)
        self._q = (0.0, 0.0, 0.0, 1.0)
        self._begun: float | None = None  # when the move with path axes began (None: at the next check)

    @property
    def received(self) -> bool:
        return self._t is not None

    def clear(self) -> None:
        self._t = None

    def begin(self, t: float | None) -> None:
        """A move with path axes begins at `t` [s] (None: at the next `check`): it waits up to `timeout` for
        a live reference before the reference counts as lost."""
        self._begun = t

    def set(self, position: Sequence[float], quaternion: Sequence[float], twist: Sequence[float],
            t: float, horizon: Sequence[tuple[Sequence[float], Sequence[float]]] = (),
            step: float = 0.0) -> str:
        """A new reference at time `t` [s]: position [m], quaternion (x, y, z, w), twist (vx..wz) [m/s, rad/s]
        in the fixed frame, and its horizon: (position, quaternion) `step`, 2 `step`, ... [s] after. Returns
        '' or why it is refused (not finite, not a rotation, a horizon without a positive step); a refused
        reference changes nothing."""
        values = (*position, *quaternion, *twist, t)
        sizes = (len(position), len(quaternion), len(twist))
        if sizes != (3, 4, 6) or not all(map(math.isfinite, values)):
            return "path reference: expected finite position (3), quaternion (4) and twist (6)"
        if abs(sum(q * q for q in quaternion) - 1.0) > 0.01:
            return "path reference: the quaternion is not a unit quaternion"
        if horizon:
            if not (math.isfinite(step) and step > 0.0):
                return f"path reference: a horizon needs horizon_step > 0, got {step}"
            for p, q in horizon:
                if len(p) != 3 or len(q) != 4 or not all(map(math.isfinite, (*p, *q))):
                    return "path reference: expected finite positions (3) and quaternions (4) in the horizon"
                if abs(sum(c * c for c in q) - 1.0) > 0.01:
                    return "path reference: a horizon quaternion is not a unit quaternion"
        self._p = (float(position[0]), float(position[1]), float(position[2]))
        self._q = (float(quaternion[0]), float(quaternion[1]), float(quaternion[2]), float(quaternion[3]))
        self._r = quaternion_matrix(*quaternion)
        self._v = tuple(float(x) for x in twist)  # type: ignore[assignment]
        self._ahead = [(tuple(p), tuple(q)) for p, q in horizon]
        self._step = float(step)
        self._t = t
        return ""

    def _along_horizon(self, age: float) -> tuple[tuple[float, ...], list[list[float]], tuple[float, ...]]:
        """Position, rotation and twist `age` s after the reference, between the horizon's poses (position
        linear, orientation normalised-linear: a step's rotation is small); past its end it stands still."""
        poses = [(self._p, self._q), *self._ahead]
        k = int(age / self._step)
        if k >= len(poses) - 1:
            p, q = poses[-1]
            return p, quaternion_matrix(*q), (0.0,) * 6
        s = age / self._step - k
        (p0, q0), (p1, q1) = poses[k], poses[k + 1]
        sign = 1.0 if sum(a * b for a, b in zip(q0, q1, strict=True)) >= 0.0 else -1.0
        mid = [(1.0 - s) * a + s * sign * b for a, b in zip(q0, q1, strict=True)]
        w = rotation_vector(times_transpose(quaternion_matrix(*q1), quaternion_matrix(*q0)))
        step = self._step
        v = tuple((p1[i] - p0[i]) / step for i in range(3)) + tuple(x / step for x in w)
        return tuple(a + s * (b - a) for a, b in zip(p0, p1, strict=True)), quaternion_matrix(*mid), v

    def age(self, t: float) -> float:
        return math.inf if self._t is None else t - self._t

    def error(self, t: float, T_fixed_eef: Matrix, R_fixed_control: Matrix | None,
              error: list[float], velocity: list[float]) -> bool:
        """Writes e and v_ref along the control axes at `t`; False (nothing written) when the reference is
        missing or older than `timeout`."""
        if self._t is None or t - self._t > self.timeout:
            return False
        m = as_rows(T_fixed_eef)
        age = max(t - self._t, 0.0)
        if age > self.extrapolate and self._ahead:
            p, r, v = self._along_horizon(age)
            dt = 0.0
        else:
            dt = min(age, self.extrapolate)
            p, r = self._p, self._r
            # Past `extrapolate` the reference stands still: fed forward on, its velocity carried the tool
            # v / k past the last point (a stalled replay ran a UR3 12 mm past the L's corner).
            v = self._v if age <= self.extrapolate else (0.0,) * 6
        e = [p[i] + v[i] * dt - m[i][3] for i in range(3)]
        e.extend(rotation_vector(times_transpose(r, m)))  # R_ref R_eef^T: the rotation still to go
        rc = _IDENTITY if R_fixed_control is None else as_rows(R_fixed_control)
        for k in (0, 3):
            for i in range(3):  # Rc^T x: along the control axes
                error[k + i] = rc[0][i] * e[k] + rc[1][i] * e[k + 1] + rc[2][i] * e[k + 2]
                velocity[k + i] = rc[0][i] * v[k] + rc[1][i] * v[k + 1] + rc[2][i] * v[k + 2]
        return True

    def check(self, t: float, T_fixed_eef: Matrix | None, R_fixed_control: Matrix | None, laws: LawSet,
              error: list[float], velocity: list[float]) -> tuple[int, int]:
        """The path axes' end this cycle, as (axis, End): PATH_LOST without a pose or a live reference,
        PATH_ERROR for an axis `max_travel` or more off the path; (-1, 0) otherwise (e and v_ref written:
        `error`)."""
        if not laws.path_axes:
            return -1, 0
        if self._begun is None:
            self._begun = t
        if T_fixed_eef is None or not self.error(t, T_fixed_eef, R_fixed_control, error, velocity):
            if T_fixed_eef is None or t - self._begun > self.timeout:
                return laws.path_axes[0], End.PATH_LOST
            for i in laws.path_axes:  # the stream's first reference is on its way: stand still meanwhile
                error[i] = velocity[i] = 0.0
        for i in laws.path_axes:
            if 0.0 < laws.laws[i].max_travel <= abs(error[i]):
                return i, End.PATH_ERROR
        return -1, 0
