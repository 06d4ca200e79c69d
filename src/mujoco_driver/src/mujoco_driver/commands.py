"""Turn the fields of the driver's command messages into :class:`~mujoco_driver.sim.Simulation` commands.

Plain data in, arrays out, no ROS: the node copies the message fields (names, lists, seconds) and calls
these; every check raises :class:`~mujoco_driver.sim.CommandError` with a message meant for a log line,
so a bad message changes nothing.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence

import numpy as np

from mujoco_driver.sim import CommandError, TrajectoryPoint

__all__ = ["RawPoint", "trajectory_points", "velocity_vector"]

# One trajectory_msgs/JointTrajectoryPoint: (positions, velocities, time_from_start [s]).
RawPoint = tuple[Sequence[float], Sequence[float], float]


def velocity_vector(data: Sequence[float], joint_names: Sequence[str]) -> np.ndarray:
    """Joint velocities of a std_msgs/Float64MultiArray, in ``joint_names`` order (as ros_control's
    joint_group_velocity_controller: one value per joint, in the controller's joint order).

    Raises:
        CommandError: On a wrong length or non-finite values.
    """
    values = np.array(data, dtype=float)
    if values.shape != (len(joint_names),):
        raise CommandError(
            f"velocity command: expected {len(joint_names)} values (joints {list(joint_names)}), "
            f"got {values.size}"
        )
    if not np.all(np.isfinite(values)):
        raise CommandError(f"velocity command: values must be finite, got {values.tolist()}")
    return values


def trajectory_points(
    names: Sequence[str],
    points: Sequence[RawPoint],
    joint_indices: Callable[[Sequence[str]], np.ndarray],
    hold: np.ndarray,
) -> list[TrajectoryPoint]:
    """Full-length trajectory points from a trajectory_msgs/JointTrajectory's joint names and points.

    Joints the message leaves out keep ``hold`` (the current setpoint) at zero velocity, as a position
    controller holds joints nobody commands.

    Args:
        names: The message's joint_names.
        points: (positions, velocities, time_from_start [s]) per point; velocities may be empty.
        joint_indices: Maps names to positions in the simulation's joint order (raises CommandError).
        hold: Current position setpoint, simulation order.

    Returns:
        Points in the simulation's joint order (velocities None when the message point has none).

    Raises:
        CommandError: No names or points, duplicate or unknown names, wrong lengths, non-finite values.
    """
    if not names:
        raise CommandError("trajectory: no joint_names")
    if len(set(names)) != len(names):
        raise CommandError(f"trajectory: duplicate joint_names {list(names)}")
    if not points:
        raise CommandError("trajectory: no points")
    index = joint_indices(names)
    result = []
    for i, (positions, velocities, seconds) in enumerate(points):
        if len(positions) != len(names):
            raise CommandError(
                f"trajectory point {i}: {len(positions)} positions for {len(names)} joint_names"
            )
        if len(velocities) not in (0, len(names)):
            raise CommandError(
                f"trajectory point {i}: {len(velocities)} velocities for {len(names)} joint_names"
            )
        if not (all(math.isfinite(v) for v in positions) and all(math.isfinite(v) for v in velocities)):
            raise CommandError(f"trajectory point {i}: values must be finite")
        q = hold.copy()
        q[index] = positions
        qd = None
        if len(velocities):
            qd = np.zeros_like(hold)
            qd[index] = velocities
        result.append(TrajectoryPoint(q, qd, float(seconds)))
    return result
