"""A path at a force as a task, and how well it was run (no ROS here).

`path_task` turns a goal (the tool tip's poses on the part, z along the tool's axis into it) into a task of
four steps: to the path's start `standoff` back along the tool's axis, coming along that axis for the last
5 cm (free space, every axis on the path law), along the tool's axis until it touches, pressing while the
tool turns onto the surface's normal, then along the path, pressing along the tool's axis (laws in the
tool's frame). `PathMetrics` measures the last step. See the package README, *Paths at a force*.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from compliant_common.typedefs import FloatArray
from contact_control.frames import matrix_quaternion, transform
from contact_control.normal import SLIP_SPEED

from contact_tasks.path import PosePath
from contact_tasks.task import Task, TaskError
from contact_tasks.task_file import parse_task

__all__ = ["ARRIVE_TIME", "CLEARANCE", "MAX_LAG", "ORIENTATIONS", "PATH_STIFFNESS", "RAMP", "PathGoal",
           "PathMetrics", "path_task"]

#: normal: the tool's axis on the contact normal, the path's turn about it; path: the path's orientation;
#: free: normal, and the turn about the tool's axis left as it is.
ORIENTATIONS = ("normal", "path", "free")
CONTACT_FORCE = 3.0  # [N] |F| above which a sample counts as in contact (contact_control's touch force)
_TO_START_SPEED = 0.05  # [m/s] in free space (a guess: a cautious cobot speed, within the collaborative cap)
_TOUCH_SPEED = 0.006  # [m/s] a stiff part met faster overshoots the touch's 5 N (the wipe task's)
MAX_LAG = 0.05  # [m] the tool may fall this far behind the path's reference (an arm slowed by a singularity)
PATH_STIFFNESS = 5.0  # [1/s] the path law's k on the translations, to the start and along the path
_PRESS_DAMPING = 2000.0  # [N/(m/s)] force tracking's b (1000 rang between 5 and 14 N through a UR's latency)
CLEARANCE = 0.05  # [m] the move to the start comes along the tool's axis over this much more than standoff
RAMP = 0.5  # [s] paths speed up and slow down over this (a speed step on a part with friction sticks)
ARRIVE_TIME = 5.0  # [s] the tool may come to the path's end this long after its reference (a slowed arm)
# The press ends once the force along the tool's axis has held at least _PRESS_SETTLED of its target for
# _PRESS_TIME (the tool turns onto the normal meanwhile): ~2 s on a stiff part; a part that gives way (held
# by a spring: thesis_demos' bimanual demonstration) takes longer to build up the force. After _PRESS_LIMIT
# the path starts anyway (force tracking goes on pressing).
_PRESS_SETTLED = 0.9
_PRESS_TIME = 1.5  # [s]
_PRESS_LIMIT = 10.0  # [s]


@dataclass(frozen=True)
class PathGoal:
    """The goal in the fixed frame: `poses` rows (x, y, z, qx, qy, qz, qw); `forces` one per segment [N]
    (pressing, positive) or empty for `force`."""

    poses: Sequence[Sequence[float]]
    speed: float = 0.01
    force: float = 10.0
    forces: Sequence[float] = ()
    orientation: str = "normal"
    standoff: float = 0.02

    def segment_forces(self, segments: int) -> list[float]:
        """The pressing force of each of `segments` segments [N]: `forces`, else `force` throughout."""
        return [float(f) for f in self.forces] or [float(self.force)] * segments


def _pose_row(T: FloatArray) -> list[float]:
    return [*(float(x) for x in T[:3, 3]), *matrix_quaternion(T[:3, :3].tolist())]


def path_task(goal: PathGoal, tool: FloatArray, name: str = "follow_path") -> Task:
    """The task for `goal` with the tool now at `tool` (4x4, fixed frame).

    Raises:
        TaskError: the goal cannot be run (the reason names the field).
    """
    if goal.orientation not in ORIENTATIONS:
        raise TaskError(f"orientation: {goal.orientation!r} is not one of {', '.join(ORIENTATIONS)}")
    if not (0.0 < goal.speed <= 0.25):
        raise TaskError(f"speed: {goal.speed:g} m/s is not in (0, 0.25]")
    if not (0.0 < goal.standoff <= 0.2):
        raise TaskError(f"standoff: {goal.standoff:g} m is not in (0, 0.2]")
    try:
        path = PosePath(goal.poses, goal.speed, ramp=RAMP)
    except TaskError as err:
        raise TaskError(f"path: {err}") from None
    forces = goal.segment_forces(path.segments)
    if len(forces) != path.segments:
        raise TaskError(f"segment_forces: {len(forces)} for {path.segments} segments (one per segment)")
    if not all(0.5 <= f <= 100.0 for f in forces):
        raise TaskError(f"force: {min(forces):g}..{max(forces):g} N is outside 0.5..100 N")
    top = max(forces)
    start = np.asarray(transform(path.positions[0], path.quaternions[0]))
    standoff, far = start.copy(), start.copy()
    standoff[:3, 3] -= goal.standoff * start[:3, 2]
    far[:3, 3] -= (goal.standoff + CLEARANCE) * start[:3, 2]
    held = {"law": "path", "stiffness": PATH_STIFFNESS, "max_travel": MAX_LAG}
    turned = {"law": "path", "stiffness": 2.0, "max_travel": 0.3}
    free_space = {"x": held, "y": held, "z": held, "rx": turned, "ry": turned, "rz": turned}
    approach = [_pose_row(tool), _pose_row(far), _pose_row(standoff)]
    to_start = PosePath(approach, _TO_START_SPEED, 0.3, RAMP)
    # force tracking's target is the force as the sensor reads it: the part pushes the tool back along -z
    press = {"law": "force_tracking", "target_force": -forces[0], "damping": _PRESS_DAMPING,
             "velocity": 0.005,
             "force_limit": 2.0 * top}
    normal = {"law": "normal", "stiffness": 2.0, "velocity": 0.1, "max_travel": math.pi}
    pressing = {"z": press} if goal.orientation == "path" else {"z": press, "rx": normal, "ry": normal}
    tilt = normal if goal.orientation != "path" else turned
    follow = {"z": press, "x": held, "y": held, "rx": tilt, "ry": tilt}
    if goal.orientation != "free":
        follow["rz"] = turned
    ceiling = 2.0 * top + 5.0
    data = {
        "task": name,
        "description": f"a {path.length:.3f} m path at {goal.speed:g} m/s pressing {top:g} N",
        "approach": "z", "approach_frame": "tool",
        "force_ceiling": ceiling, "torque_ceiling": 5.0,
        "time_limit": to_start.duration + path.duration + 60.0,
        "retract": {"distance": goal.standoff, "speed": 0.01, "force_limit": min(20.0, ceiling)},
        "steps": {
            "to_start": {
                "laws": free_space, "frame": "fixed",
                "pattern": {"type": "path", "poses": approach,
                            "speed": _TO_START_SPEED, "angular_speed": 0.3, "ramp": RAMP},
                "exits": [{"when": "timeout", "after": to_start.duration + 0.5, "next": "touch"},
                          {"when": "move_ended",
                           "fail": "contact_control ended the move to the path's start"}]},
            "touch": {
                "laws": {"z": {"law": "compliant_move", "velocity": _TOUCH_SPEED, "damping": 2000.0,
                               "force_limit": 5.0, "max_travel": goal.standoff + 0.02}},
                "law_frame": "tool",
                "exits": [{"when": "touch", "next": "press"},
                          {"when": "move_ended",
                           "fail": f"no contact within {goal.standoff + 0.02:g} m along the tool's axis from "
                           "the path's start"}]},
            "press": {
                "laws": pressing, "law_frame": "tool",
                # the law frame's z is the tool's: the part pushes the tool back along -z
                "exits": [{"when": "force", "axis": "z", "below": -_PRESS_SETTLED * forces[0],
                           "for": _PRESS_TIME, "next": "follow"},
                          {"when": "timeout", "after": _PRESS_LIMIT, "next": "follow"},
                          {"when": "move_ended", "fail": "contact_control ended the press"}]},
            "follow": {
                "laws": follow, "law_frame": "tool", "frame": "fixed",
                "pattern": {"type": "path", "poses": [list(map(float, row)) for row in goal.poses],
                            "speed": goal.speed, "forces": [-f for f in forces], "ramp": RAMP},
                "exits": [{"when": "pattern_done", "succeed": f"ran the path's {path.length:.3f} m"},
                          {"when": "move_ended", "fail": "contact_control ended the move along the path"},
                          {"when": "timeout", "after": path.duration + ARRIVE_TIME,
                           "fail": f"the tool was not at the path's end {ARRIVE_TIME:g} s after its "
                           "reference (an arm slowed near a singularity or a joint limit: jog_arm's "
                           "~status)"}]},
        },
    }
    return parse_task(data, "<follow_path goal>")


class PathMetrics:
    """Samples of the run along the path: the force along the tool's axis against its target, contact, the
    tool's axis to the contact normal as the force reads it while the tool slides (the sliding friction
    `friction` predicts taken out, as contact_control's normal law does; a tool that sticks hides the normal
    behind static friction), the sideways error. Fed once per observation of the follow step."""

    def __init__(self, path: PosePath, forces: Sequence[float], friction: float = 0.0) -> None:
        self.path = path
        self.forces = list(forces)
        self.friction = friction
        self.force_errors: list[float] = []
        self.force_max = 0.0
        self.contacts = 0
        self.angles: list[float] = []  # [rad], in contact
        self.laterals: list[float] = []  # [m]
        self.t0: float | None = None
        self.t1 = 0.0
        self._last: tuple[float, FloatArray] | None = None

    def add(self, t: float, tool: FloatArray, wrench: Sequence[float],
            segment: int) -> tuple[float, float, float]:
        """One sample: `tool` 4x4 (fixed frame), `wrench` in the tool's frame (the laws' frame), the
        reference's `segment`. Returns (force along the axis [N, pressing positive], path error [m], angle
        to the force's direction [rad] or 0 out of contact)."""
        if self.t0 is None:
            self.t0 = t
        self.t1 = t
        f = np.asarray(wrench[:3], dtype=float)
        size = float(np.linalg.norm(f))
        pressing = -float(f[2])
        self.force_errors.append(pressing - self.forces[segment])
        self.force_max = max(self.force_max, size)
        _, off, i = self.path.nearest(tool[:3, 3].tolist())
        angle = 0.0
        position, last = tool[:3, 3].copy(), self._last
        self._last = (t, position)
        sliding = last is not None and t > last[0] and \
            float(np.linalg.norm(position - last[1])) >= SLIP_SPEED * (t - last[0])
        if size > CONTACT_FORCE:
            self.contacts += 1
        if size > CONTACT_FORCE and sliding:
            # friction pushes back along the slide: add it back to read the normal (tool axes)
            normal = f + self.friction * max(pressing, 0.0) * (tool[:3, :3].T @ self.path.tangent(i))
            angle = math.acos(max(-1.0, min(1.0, -float(normal[2]) / float(np.linalg.norm(normal)))))
            self.angles.append(angle)
        axis = tool[:3, 2]
        in_plane = off - (off @ axis) * axis
        side = np.cross(axis, self.path.tangent(i))
        norm = float(np.linalg.norm(side))
        lateral = abs(float(in_plane @ side)) / norm if norm > 1e-9 else float(np.linalg.norm(in_plane))
        self.laterals.append(lateral)
        return pressing, float(np.linalg.norm(in_plane)), angle

    def summary(self) -> dict[str, float]:
        """force_rms_error, force_max, contact_fraction, normal_angle_rms/max [deg], lateral_error_rms/max,
        duration."""
        n = len(self.force_errors)

        def rms(values: Sequence[float]) -> float:
            return math.sqrt(sum(v * v for v in values) / len(values)) if values else 0.0

        return {
            "force_rms_error": rms(self.force_errors),
            "force_max": self.force_max,
            "contact_fraction": self.contacts / n if n else 0.0,
            "normal_angle_rms": math.degrees(rms(self.angles)),
            "normal_angle_max": math.degrees(max(self.angles, default=0.0)),
            "lateral_error_rms": rms(self.laterals),
            "lateral_error_max": max(self.laterals, default=0.0),
            "duration": self.t1 - (self.t0 if self.t0 is not None else self.t1),
        }
