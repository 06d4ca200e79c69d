"""The normal law's estimate (LAW_NORMAL on RX/RY): the contact normal from the measured force, followed at a
bounded rate, and the rotation that turns the tool's axis onto it (README, *Keeping the tool normal*; no ROS).

The surface pushes the tool along its normal, plus friction against the sliding direction: the normal is
the contact force with the friction a coefficient `friction` predicts (mu |F . axis| against the tool's
sliding) added back. The followed normal turns toward that estimate at most `max_rate`; an estimate more
than `jump` away from it (an edge, a lift-off and a landing elsewhere) is not followed: the tool holds its
orientation and `message` says why until the estimate comes back. Below `min_force` there is no contact to
read and the tool holds its orientation too; a move's first normal is taken once the estimate has settled.
Vectors are in the fixed frame, so a control frame that turns with the tool does not move the normal.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

from contact_control.laws import AxisLaw
from contact_control.params import ContactControlSettings
from contact_control.preprocess import Matrix

__all__ = ["NormalFollower", "Vec3", "normal_velocity"]

Vec3 = tuple[float, float, float]
_ZERO: Vec3 = (0.0, 0.0, 0.0)
# The first normal of a move: the estimate within this angle of where it was for this long (a guess: the
# wrench's 5 Hz low-pass alone takes ~0.1 s to settle after a touch).
SETTLE_ANGLE = 0.035  # [rad], 2 degrees
SETTLE_TIME = 0.2  # [s]
# The sliding speed from which friction is taken as fully developed (a guess); slower, in proportion: a
# press along a turned tool's axis moves it across the axis by a hair, which is no slide.
SLIP_SPEED = 0.002  # [m/s]


def _dot(a: Sequence[float], b: Sequence[float]) -> float:
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def _cross(a: Sequence[float], b: Sequence[float]) -> Vec3:
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def _unit(a: Sequence[float]) -> Vec3 | None:
    n = math.sqrt(_dot(a, a))
    return None if n < 1e-12 else (a[0] / n, a[1] / n, a[2] / n)


def _angle(a: Vec3, b: Vec3) -> float:
    """The angle between unit vectors a and b [rad] (atan2: exact near 0 and pi)."""
    c = _cross(a, b)
    return math.atan2(math.sqrt(_dot(c, c)), _dot(a, b))


def _turn(a: Vec3, b: Vec3, angle: float) -> Vec3:
    """Unit vector a turned by `angle` toward unit vector b, in their plane."""
    s = _unit(_cross(a, b))
    if s is None:
        return a
    w = _cross(s, a)  # in the plane, perpendicular to a, toward b
    c, n = math.cos(angle), math.sin(angle)
    return (c * a[0] + n * w[0], c * a[1] + n * w[1], c * a[2] + n * w[2])


class NormalFollower:
    """The followed contact normal of one move; `step` each cycle, `reset` when laws are set.

    Args:
        min_force: |F| [N] below which there is no contact to read (orientation held).
        max_rate: the followed normal turns at most this fast [rad/s].
        jump: an estimate this far [rad] from the followed normal is not followed.
        friction: the sliding friction coefficient mu between tool and surface (0: none assumed).
    """

    def __init__(self, min_force: float = 3.0, max_rate: float = 0.15, jump: float = 0.2,
                 friction: float = 0.0) -> None:
        self.min_force, self.max_rate, self.jump, self.friction = min_force, max_rate, jump, friction
        self._normal: Vec3 | None = None
        self._candidate: Vec3 | None = None
        self._steady = 0.0
        self.message = ""

    @classmethod
    def of(cls, s: ContactControlSettings) -> NormalFollower:
        """One with the node's `normal_*` settings."""
        return cls(s.normal_min_force, s.normal_max_rate, s.normal_jump, s.normal_friction)

    def tune(self, s: ContactControlSettings) -> None:
        """The node's `normal_*` settings, changed live; the followed normal stays."""
        self.min_force, self.max_rate, self.jump, self.friction = (
            s.normal_min_force, s.normal_max_rate, s.normal_jump, s.normal_friction)

    def reset(self) -> None:
        """A new move: the normal is read afresh once the contact has settled."""
        self._normal, self.message = None, ""
        self._candidate, self._steady = None, 0.0

    def _settled(self, seen: Vec3, dt: float) -> bool:
        """The first normal of a move is taken once the estimate has stayed within SETTLE_ANGLE for
        SETTLE_TIME: while the tool still moves onto the surface, friction leans the force (README)."""
        if self._candidate is None or _angle(self._candidate, seen) > SETTLE_ANGLE:
            self._candidate, self._steady = seen, 0.0
            return False
        self._steady += dt
        return self._steady >= SETTLE_TIME

    @property
    def normal(self) -> Vec3 | None:
        """The followed normal (unit, pointing out of the surface), None before the first contact."""
        return self._normal

    def estimate(self, force: Sequence[float], axis: Vec3, velocity: Sequence[float]) -> Vec3 | None:
        """The normal this force says (unit, out of the surface), None below `min_force`.

        Args:
            force: the contact force on the tool [N].
            axis: the tool's axis (unit).
            velocity: the tool's commanded linear velocity [m/s]: its part across the axis is the sliding.
        """
        if _dot(force, force) < self.min_force * self.min_force:
            return None
        if self.friction > 0.0:
            along = _dot(velocity, axis)
            slide = [velocity[i] - along * axis[i] for i in range(3)]
            speed = math.sqrt(_dot(slide, slide))
            if speed > 0.0:  # friction pushed back against the slide: add it back, full once it slides
                mu_n = self.friction * abs(_dot(force, axis)) * min(speed, SLIP_SPEED) / (SLIP_SPEED * speed)
                force = [force[i] + mu_n * slide[i] for i in range(3)]
        return _unit(force)

    def step(self, force: Sequence[float], axis: Vec3, velocity: Sequence[float], dt: float) -> Vec3:
        """The rotation vector [rad] that turns the tool's `axis` onto the followed normal (into the surface),
        zero while the orientation holds (no contact, or a jump not followed)."""
        seen = self.estimate(force, axis, velocity)
        if seen is None:
            self.message = ""
            return _ZERO
        followed = self._normal
        if followed is None:
            if not self._settled(seen, dt):
                return _ZERO
            followed = seen
        else:
            off = _angle(followed, seen)
            if off > self.jump:
                self.message = (f"normal law: the contact normal jumped {math.degrees(off):.1f} deg from the "
                                f"followed one (more than normal_jump {math.degrees(self.jump):.1f} deg): "
                                "not followed, the tool's orientation holds")
                return _ZERO
            step = self.max_rate * dt
            followed = seen if off <= step else _turn(followed, seen, step)
        self._normal, self.message = followed, ""
        # The tool points into the surface: its axis goes to -normal, or +normal for a sensor whose z axis
        # points away from the tool (the side the axis is on now decides).
        along = _dot(axis, followed)
        sign = 1.0 if along > 0.0 else -1.0
        c = _cross(axis, followed)
        size = math.sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2])
        if size < 1e-12:
            return _ZERO
        k = sign * math.atan2(size, sign * along) / size  # the angle to the target, along the unit cross
        return (c[0] * k, c[1] * k, c[2] * k)

    def control_step(self, wrench: Sequence[float], velocity: Sequence[float], dt: float,
                     T_control_sensor: Matrix | None, R_fixed_control: Matrix | None) -> Vec3:
        """`step` in the controller's terms: wrench and velocity along the control frame's axes, the tool's
        axis the sensor's z (T_control_sensor; None: the control frame's z), the control frame's orientation
        in the fixed frame (None: the fixed frame itself). The turn comes back along the control axes."""
        T = T_control_sensor
        axis: Vec3 = (0.0, 0.0, 1.0) if T is None else (T[0][2], T[1][2], T[2][2])
        R = R_fixed_control
        if R is None:
            return self.step(wrench[:3], axis, velocity[:3], dt)
        turn = self.step(_times(R, wrench), _times(R, axis), _times(R, velocity), dt)
        return (R[0][0] * turn[0] + R[1][0] * turn[1] + R[2][0] * turn[2],
                R[0][1] * turn[0] + R[1][1] * turn[1] + R[2][1] * turn[2],
                R[0][2] * turn[0] + R[1][2] * turn[1] + R[2][2] * turn[2])


def _times(R: Matrix, v: Sequence[float]) -> Vec3:
    """R v for a 3x3 R and the first three values of v."""
    return (R[0][0] * v[0] + R[0][1] * v[1] + R[0][2] * v[2],
            R[1][0] * v[0] + R[1][1] * v[1] + R[1][2] * v[2],
            R[2][0] * v[0] + R[2][1] * v[1] + R[2][2] * v[2])


def normal_velocity(law: AxisLaw, angle: float) -> float:
    """The normal law's angular velocity before shaping: W = k theta, theta this axis's part of the turn onto
    the contact normal (`NormalFollower`); at most `velocity` when that is > 0."""
    w = law.stiffness * angle
    cap = law.velocity
    if cap > 0.0 and not -cap <= w <= cap:
        return cap if w > 0.0 else -cap
    return w
