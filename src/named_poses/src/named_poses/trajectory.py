"""A planned joint trajectory checked and followed (control_msgs/FollowJointTrajectory; no ROS here).

`Planned.check` turns a goal's joint names, points and tolerances into arrays in the pose joints' order, or
refuses it (`TrajectoryError`, with control_msgs' error code). `Planned.desired` samples where the arm
should be t seconds in (cubic Hermite between points with velocities, else linear), `Planned.off_path`
names the first joint past its path tolerance and `Planned.off_goal` those past their goal tolerance.
README, *FollowJointTrajectory*.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np

from named_poses.poses import PoseError, UrdfJoint

__all__ = ["INVALID_GOAL", "INVALID_JOINTS", "Planned", "Tolerance", "TrajectoryError"]

# control_msgs/FollowJointTrajectoryResult's codes this module refuses with.
INVALID_GOAL = -1
INVALID_JOINTS = -2


class TrajectoryError(PoseError):
    """A trajectory goal that cannot run; `code` is control_msgs' error code, the message says why."""

    def __init__(self, code: int, message: str) -> None:
        super().__init__(message)
        self.code = code


@dataclass(frozen=True)
class Tolerance:
    """A goal's JointTolerance, by name: position [rad or m] (0: the default, < 0: none)."""

    name: str
    position: float


@dataclass(frozen=True)
class Planned:
    """A checked trajectory in the pose joints' order.

    Attributes:
        times: time from start of each point [s], increasing, the first >= 0.
        positions: (points, joints) [rad or m].
        velocities: (points, joints), or None when the points give none (linear between points).
        path_tolerance, goal_tolerance: per joint [rad or m]; inf: none.
        goal_time: how long after the last point the arm may take to get within the goal tolerance [s].
    """

    times: np.ndarray
    positions: np.ndarray
    velocities: np.ndarray | None
    path_tolerance: np.ndarray
    goal_tolerance: np.ndarray
    goal_time: float

    @property
    def duration(self) -> float:
        return float(self.times[-1])

    @classmethod
    def check(cls, joints: Sequence[str], limits: Mapping[str, UrdfJoint], names: Sequence[str],
              points: Sequence[tuple[float, Sequence[float], Sequence[float]]],
              path_tolerance: Sequence[Tolerance], goal_tolerance: Sequence[Tolerance], goal_time: float,
              default_path: float, default_goal: float, default_goal_time: float) -> Planned:
        """The goal as arrays, or TrajectoryError naming what is wrong.

        Args:
            joints: the arm's joints (named_poses' pose joints), the order of the arrays.
            limits: the URDF's joints (position limits).
            names: the trajectory's joint names (every arm joint, any order, no other).
            points: (time from start [s], positions, velocities or empty) per point.
            path_tolerance, goal_tolerance: the goal's, by joint name (others: the defaults).
            goal_time: the goal's goal_time_tolerance [s] (0: `default_goal_time`).
            default_path, default_goal: the server's tolerances [rad or m] (path: inf for none).
        """
        if len(set(names)) != len(names):
            raise TrajectoryError(INVALID_JOINTS, f"joint names repeat: {list(names)}")
        unknown, missing = sorted(set(names) - set(joints)), [j for j in joints if j not in names]
        if unknown or missing:
            raise TrajectoryError(INVALID_JOINTS, f"the trajectory must name the arm's joints "
                                  f"{list(joints)}" + (f"; unknown: {unknown}" if unknown else "")
                                  + (f"; missing: {missing}" if missing else ""))
        if not points:
            raise TrajectoryError(INVALID_GOAL, "the trajectory has no points")
        order = [list(names).index(j) for j in joints]
        times: list[float] = []
        positions: list[list[float]] = []
        velocities: list[list[float]] = []
        with_velocities = all(len(v) for _t, _q, v in points)
        for i, (t, pos, v) in enumerate(points):
            if len(pos) != len(names) or (with_velocities and len(v) != len(names)):
                raise TrajectoryError(INVALID_GOAL, f"point {i}: {len(pos)} positions, {len(v)} velocities "
                                      f"for {len(names)} joints")
            if not (math.isfinite(t) and all(map(math.isfinite, pos)) and all(map(math.isfinite, v))):
                raise TrajectoryError(INVALID_GOAL, f"point {i}: not a finite number")
            if t < 0.0 or (times and t <= times[-1]):
                raise TrajectoryError(INVALID_GOAL, f"point {i}: time_from_start {t:g} s must increase "
                                        "from >= 0")
            times.append(t)
            positions.append([pos[k] for k in order])
            velocities.append([v[k] for k in order] if with_velocities else [])
        q = np.array(positions)
        for k, joint in enumerate(joints):
            low, high = limits[joint].lower, limits[joint].upper
            bad = np.flatnonzero((q[:, k] < low - 1e-9) | (q[:, k] > high + 1e-9))
            if bad.size:
                raise TrajectoryError(INVALID_GOAL, f"point {int(bad[0])}: {joint} at {q[bad[0], k]:.4f} "
                                      f"is outside its URDF limits [{low:.4f}, {high:.4f}]")
        return cls(np.array(times), q, np.array(velocities) if with_velocities else None,
                   _tolerances(joints, path_tolerance, default_path, "path_tolerance"),
                   _tolerances(joints, goal_tolerance, default_goal, "goal_tolerance"),
                   goal_time if goal_time > 0.0 else default_goal_time)

    def desired(self, t: float, start: np.ndarray) -> np.ndarray:
        """Where the arm should be `t` s in; before the first point, on the way from `start` (where it
        was)."""
        times, q = self.times, self.positions
        if t >= times[-1]:
            return q[-1]
        i = int(np.searchsorted(times, t, side="right"))  # times[i - 1] <= t < times[i]
        t0, q0 = (0.0, start) if i == 0 else (times[i - 1], q[i - 1])
        h, s = times[i] - t0, (t - t0) / (times[i] - t0)
        if self.velocities is None or i == 0:
            return q0 + s * (q[i] - q0)
        v0, v1 = self.velocities[i - 1], self.velocities[i]
        s2, s3 = s * s, s * s * s
        return ((2 * s3 - 3 * s2 + 1) * q0 + (s3 - 2 * s2 + s) * h * v0 + (-2 * s3 + 3 * s2) * q[i]
                + (s3 - s2) * h * v1)

    def off_path(self, actual: np.ndarray, desired: np.ndarray) -> int:
        """The first joint further than its path tolerance from where it should be, -1 if none."""
        over = np.flatnonzero(np.abs(actual - desired) > self.path_tolerance)
        return int(over[0]) if over.size else -1

    def off_goal(self, actual: np.ndarray) -> list[int]:
        """The joints further than their goal tolerance from the last point."""
        return [int(k) for k in np.flatnonzero(np.abs(actual - self.positions[-1]) > self.goal_tolerance)]


def _tolerances(joints: Sequence[str], given: Sequence[Tolerance], default: float, key: str) -> np.ndarray:
    """Per joint: the goal's (0: `default`, < 0: none), else `default`."""
    out = np.full(len(joints), default)
    for tol in given:
        if tol.name not in joints:
            raise TrajectoryError(INVALID_JOINTS, f"{key} names {tol.name!r}, not a joint of the arm "
                                    f"{list(joints)}")
        if tol.position != 0.0:
            out[list(joints).index(tol.name)] = math.inf if tol.position < 0.0 else tol.position
    return out
