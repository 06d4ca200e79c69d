"""What the RViz view draws, as plain values (no ROS; the node turns them into visualization_msgs): the laws
per axis as text, the commanded velocity as an arrow, the simulated obstacle and push, and the paths of a
replay (its reference and where the tool went). See the package README."""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np
import pinocchio as pin

__all__ = [
    "ARROW_SECONDS", "AxisLine", "Box", "Trail", "axis_text", "cap_text", "obstacle_box", "velocity_arrow",
]

ARROW_SECONDS = 2.0  # the velocity arrow is this many seconds of motion long (0.1 m/s: 0.2 m)
MIN_ARROW = 1e-4  # [m/s] slower than this draws no arrow


@dataclass(frozen=True)
class AxisLine:
    """One axis as the status reports it."""

    axis: str
    law: str  # none, follower, spring, compliant_move, force_tracking, path
    force: float  # [N] or [Nm]
    velocity: float  # commanded [m/s] or [rad/s]
    end: str = ""  # the end condition's words ('' or "none" while running)
    reacting: bool = False  # carrying out its exceeded action


def axis_text(lines: Sequence[AxisLine], safety: str = "ok", message: str = "") -> str:
    """The laws and their state, one line per axis that has a law, then safety when not ok."""
    rows = []
    for a in lines:
        ended = a.end not in ("", "none")
        if a.law == "none" and not ended:
            continue
        rotational = a.axis.startswith("r")
        unit, vunit, scale = ("Nm", "deg/s", 180.0 / math.pi) if rotational else ("N", "mm/s", 1000.0)
        row = f"{a.axis}: {a.law}  {a.force:+.1f} {unit}  {a.velocity * scale:+.1f} {vunit}"
        if a.reacting:
            row += "  (reacting)"
        elif ended:
            row += f"  [{a.end}]"
        rows.append(row)
    if not rows:
        rows.append("no law")
    if safety != "ok":
        rows.append(f"SAFETY: {safety}" + (f" ({message})" if message else ""))
    return "\n".join(rows)


def cap_text(speed_cap: float, region: str, capped: bool) -> str:
    """jog_arm's collaborative speed cap (its status' `speed_cap`, `body_region`, and whether it slows the
    motion now): '' while nothing translates or the cap is off."""
    if not math.isfinite(speed_cap) or region in ("", "off"):
        return ""
    return f"{'CAPPED at' if capped else 'speed cap'} {speed_cap:.2f} m/s ({region}, ISO/TS 15066)"


def velocity_arrow(tip: Sequence[float], linear: Sequence[float]) -> tuple[np.ndarray, np.ndarray] | None:
    """(start, end) of the arrow for a linear velocity at the tool tip, both in the velocity's frame; None
    when it is too slow to draw."""
    v = np.asarray(linear, dtype=float)
    if not np.all(np.isfinite(v)) or float(np.linalg.norm(v)) < MIN_ARROW:
        return None
    start = np.asarray(tip, dtype=float)
    return start, start + ARROW_SECONDS * v


@dataclass(frozen=True)
class Box:
    """A box: centre [m], roll-pitch-yaw [rad], full size [m]."""

    position: tuple[float, float, float]
    rpy: tuple[float, float, float]
    size: tuple[float, float, float]

    def quaternion(self) -> tuple[float, float, float, float]:
        """(x, y, z, w) of its roll-pitch-yaw (URDF's convention, Pinocchio's rpyToMatrix)."""
        x, y, z, w = pin.Quaternion(pin.rpy.rpyToMatrix(*self.rpy)).coeffs()
        return float(x), float(y), float(z), float(w)


def obstacle_box(scene: Mapping[str, object]) -> Box | None:
    """The obstacle of a mujoco_driver scene YAML (its `obstacle` mapping), None without one or when it is
    malformed (the driver refuses those; the view just does not draw it)."""
    obs = scene.get("obstacle")
    if not isinstance(obs, Mapping):
        return None
    try:
        position = tuple(float(x) for x in obs["position"])
        size = tuple(float(x) for x in obs["size"])
        rpy = tuple(float(x) for x in obs.get("rpy", (0.0, 0.0, 0.0)))
    except (KeyError, TypeError, ValueError):
        return None
    if not (len(position) == len(size) == len(rpy) == 3):
        return None
    return Box(position, rpy, size)


class Trail:
    """Points of a path, at least `spacing` apart, at most `limit` of them (the oldest dropped); cleared by a
    gap longer than `gap` seconds (a new replay)."""

    def __init__(self, spacing: float = 0.001, limit: int = 5000, gap: float = 1.0) -> None:
        self.spacing, self.limit, self.gap = spacing, limit, gap
        self.points: list[tuple[float, float, float]] = []
        self._last_t = -math.inf

    def add(self, t: float, point: Sequence[float]) -> None:
        p = (float(point[0]), float(point[1]), float(point[2]))
        if not all(math.isfinite(x) for x in p):
            return
        if t - self._last_t > self.gap:
            self.points.clear()
        self._last_t = t
        if self.points and math.dist(self.points[-1], p) < self.spacing:
            return
        self.points.append(p)
        if len(self.points) > self.limit:
            del self.points[: len(self.points) - self.limit]
