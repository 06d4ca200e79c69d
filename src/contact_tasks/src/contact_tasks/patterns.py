"""Motion patterns: where the reference is t seconds into a step, relative to its start (no ROS here).

Each is a pure function of time, so a stalled executor resumes where the clock says. Offsets are in the
step's frame: line and spiral and lissajous move in its X/Y plane (a line along any axis), wiggle turns about
its X and Y axes. After its end (`done`) a pattern holds its last point with zero velocity.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from contact_tasks.task import Pattern

__all__ = ["PatternPoint", "evaluate", "spiral_angle"]

_AXIS = {"x": 0, "y": 1, "z": 2}


@dataclass(frozen=True)
class PatternPoint:
    """The reference relative to the step's start, in the step's frame.

    Attributes:
        offset: translation [m].
        rotation: rotation vector [rad] (wiggle only).
        twist: (vx, vy, vz [m/s], wx, wy, wz [rad/s]).
        done: the pattern has ended (it holds its last point).
        radius: distance from the start in the plane [m] (the search radius the feedback reports).
    """

    offset: tuple[float, float, float]
    rotation: tuple[float, float, float]
    twist: tuple[float, float, float, float, float, float]
    done: bool
    radius: float


_STILL = PatternPoint((0.0, 0.0, 0.0), (0.0, 0.0, 0.0), (0.0, 0.0, 0.0, 0.0, 0.0, 0.0), False, 0.0)


def spiral_angle(arc: float, a: float) -> float:
    """The angle theta [rad] where an Archimedean spiral r = a theta has run `arc` [m] along its curve:
    s(theta) = a/2 (theta sqrt(1 + theta^2) + asinh theta), solved by Newton's method."""
    if arc <= 0.0:
        return 0.0
    theta = math.sqrt(2.0 * arc / a)  # s ~ a theta^2 / 2 for large theta; a start above the root
    for _ in range(30):
        s = 0.5 * a * (theta * math.sqrt(1.0 + theta * theta) + math.asinh(theta))
        step = (s - arc) / (a * math.sqrt(1.0 + theta * theta))
        theta -= step
        if abs(step) < 1e-12:
            break
    return theta


def evaluate(pattern: Pattern, t: float) -> PatternPoint:
    """The pattern `t` seconds [s] after the step began."""
    kind = pattern.type
    if kind == "none":
        return _STILL
    t = max(t, 0.0)
    if kind == "line":
        axis = pattern.axis
        sign = -1.0 if axis.startswith("-") else 1.0
        i = _AXIS[axis.lstrip("-")]
        run = min(pattern.speed * t, pattern.distance)
        done = pattern.speed * t >= pattern.distance
        offset, twist = [0.0] * 3, [0.0] * 6
        offset[i] = sign * run
        twist[i] = 0.0 if done else sign * pattern.speed
        return PatternPoint(tuple(offset), (0.0, 0.0, 0.0), tuple(twist), done, run)  # type: ignore[arg-type]
    if kind == "spiral":
        a = pattern.pitch / (2.0 * math.pi)
        end = pattern.max_radius / a
        theta = spiral_angle(pattern.speed * t, a)
        done = theta >= end
        theta = min(theta, end)
        r = a * theta
        c, s = math.cos(theta), math.sin(theta)
        v = (0.0, 0.0)
        if not done:  # speed along the unit tangent: d/dtheta (a theta cos, a theta sin) / |...|
            norm = math.sqrt(1.0 + theta * theta)
            v = (pattern.speed * (c - theta * s) / norm, pattern.speed * (s + theta * c) / norm)
        return PatternPoint((r * c, r * s, 0.0), (0.0, 0.0, 0.0), (v[0], v[1], 0.0, 0.0, 0.0, 0.0), done, r)
    # lissajous and wiggle: sinusoids per axis until `duration`
    done = t >= pattern.duration
    t = min(t, pattern.duration)
    w = [2.0 * math.pi * f for f in pattern.frequency]
    amp = pattern.amplitude
    x, y = amp[0] * math.sin(w[0] * t), amp[1] * math.sin(w[1] * t)
    vx, vy = (0.0, 0.0) if done else (amp[0] * w[0] * math.cos(w[0] * t), amp[1] * w[1] * math.cos(w[1] * t))
    if kind == "lissajous":
        moving = (vx, vy, 0.0, 0.0, 0.0, 0.0)
        return PatternPoint((x, y, 0.0), (0.0, 0.0, 0.0), moving, done, math.hypot(x, y))
    return PatternPoint((0.0, 0.0, 0.0), (x, y, 0.0), (0.0, 0.0, 0.0, vx, vy, 0.0), done, 0.0)
