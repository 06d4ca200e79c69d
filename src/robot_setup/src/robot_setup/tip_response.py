"""How the tool tip answers the joints at a pose: the joint motion a translation takes, and the tip
acceleration a joint acceleration limit allows. The generator sizes jog_arm's acceleration limit from it
(robot_setup README, *What make robot decides*). Pure: Pinocchio through jog_arm's ArmModel, numpy; no ROS
master.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from jog_arm.kinematics import ArmModel
from jog_arm.task_priority import PriorityTask

__all__ = ["MIN_TIP_ACCELERATION", "joint_rates", "tip_acceleration"]

# make robot raises jog_arm's joint acceleration limit above its default until the tip can accelerate at least
# MIN_TIP_ACCELERATION along the base's X, Y and Z at the start pose: a small arm needs larger joint
# accelerations for the same tip motion. Below it the spring overshoots when released: the SO-100 at 3 rad/s^2
# (0.35 m/s^2 along X) came back 0.72 mm past its start (limit 10 % of 5.7 mm), at 5 rad/s^2 (0.58 m/s^2)
# 0.07 mm; the UR3 (0.56 m/s^2) and TiAGo (0.58 m/s^2) pass at the default.
MIN_TIP_ACCELERATION = 0.55  # [m/s^2]


def joint_rates(arm: ArmModel, q: np.ndarray, velocity: Sequence[float] | np.ndarray) -> np.ndarray:
    """Joint velocities [rad/s] that move the tip at `velocity` [m/s] (base axes) without turning it, as
    jog_arm solves it: the full Jacobian for six or more joints, translation first for fewer."""
    J = np.array(arm.jacobian(np.asarray(q, dtype=float)))
    twist = np.concatenate([np.asarray(velocity, dtype=float), np.zeros(3)])
    if arm.nv >= 6:
        return np.linalg.lstsq(J, twist, rcond=None)[0]
    task = PriorityTask(arm.nv)
    task.update(J, 0.0)
    return np.array(task.solve(twist))


def tip_acceleration(arm: ArmModel, q: np.ndarray, joint_acceleration: float) -> float:
    """The smallest tip acceleration [m/s^2] along the base's X, Y and Z that jog_arm's joint acceleration
    limit (every joint: `joint_acceleration` [rad/s^2]) allows at `q`."""
    worst = max(float(np.max(np.abs(joint_rates(arm, q, axis)))) for axis in np.eye(3))
    return joint_acceleration / worst
