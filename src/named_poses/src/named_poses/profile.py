"""Joint-space moves: every joint starts and stops together on a trapezoidal velocity profile.

Pure: numpy only. The path is the straight line in joint space from `start` to `goal`; one scalar
profile s(t) in [0, 1] drives all joints (q = start + s (goal - start)), with the largest speed and
acceleration of s that keep every joint within its own limits, so the move is as fast as the slowest
joint allows and no joint overshoots.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from compliant_common.errors import StackError

__all__ = ["JointMove", "MotionProfileError", "plan_move"]


class MotionProfileError(StackError):
    """Limits or positions that give no move (non-positive limits, NaN, mismatched lengths)."""


@dataclass(frozen=True)
class JointMove:
    """A sampled joint-space move.

    Attributes:
        times: Sample times from the start [s], increasing, the last = `duration`.
        positions: (N, n) joint positions [rad].
        velocities: (N, n) joint velocities [rad/s]; zero at both ends.
        duration: Total time [s].
    """

    times: np.ndarray
    positions: np.ndarray
    velocities: np.ndarray
    duration: float


def _scalar_profile(peak_speed: float, peak_accel: float) -> tuple[float, float, float]:
    """(acceleration time, cruise time, peak speed reached) of a rest-to-rest trapezoid covering s = 1."""
    if peak_speed * peak_speed / peak_accel >= 1.0:  # never reaches peak speed: a triangle
        t_acc = math.sqrt(1.0 / peak_accel)
        return t_acc, 0.0, peak_accel * t_acc
    t_acc = peak_speed / peak_accel
    return t_acc, 1.0 / peak_speed - t_acc, peak_speed


def plan_move(
    start: Sequence[float] | np.ndarray,
    goal: Sequence[float] | np.ndarray,
    max_velocity: Sequence[float] | np.ndarray,
    max_acceleration: Sequence[float] | np.ndarray,
    sample_period: float = 0.02,
    max_path_speed: float = math.inf,
) -> JointMove:
    """Plan the synchronised rest-to-rest move from `start` to `goal`.

    Args:
        start: Joint positions now [rad].
        goal: Target joint positions [rad].
        max_velocity: Per-joint velocity limits [rad/s], > 0.
        max_acceleration: Per-joint acceleration limits [rad/s^2], > 0.
        sample_period: Spacing of the samples [s] (the driver interpolates between them).
        max_path_speed: The largest ds/dt of the path s in [0, 1] (the collaborative speed cap's,
            `jog_arm.speed_cap.path_speed_limit`) [1/s], > 0.

    Returns:
        The sampled move; a single sample at t = 0 if already there.

    Raises:
        MotionProfileError: Mismatched lengths, non-finite values or non-positive limits.
    """
    q0, q1 = np.asarray(start, dtype=float), np.asarray(goal, dtype=float)
    vmax, amax = np.asarray(max_velocity, dtype=float), np.asarray(max_acceleration, dtype=float)
    if not (q0.shape == q1.shape == vmax.shape == amax.shape) or q0.ndim != 1:
        raise MotionProfileError(
            "start, goal and limits need one value per joint: "
            f"{q0.shape}, {q1.shape}, {vmax.shape}, {amax.shape}"
        )
    for label, values in (("start", q0), ("goal", q1), ("max_velocity", vmax), ("max_acceleration", amax)):
        if not np.all(np.isfinite(values)):
            raise MotionProfileError(f"{label} is not finite: {values.tolist()}")
    if np.any(vmax <= 0) or np.any(amax <= 0):
        raise MotionProfileError(
            f"limits must be positive: velocity {vmax.tolist()}, acceleration {amax.tolist()}")
    if not max_path_speed > 0:
        raise MotionProfileError(f"max_path_speed must be positive, got {max_path_speed}")
    if not sample_period > 0:
        raise MotionProfileError(f"sample_period must be positive, got {sample_period}")
    delta = q1 - q0
    moving = np.abs(delta) > 1e-12
    if not np.any(moving):
        zero = np.zeros((1, len(q0)))
        return JointMove(np.zeros(1), q1[None, :].copy(), zero, 0.0)
    # Largest ds/dt and d2s/dt2 that keep every moving joint within its limits.
    speed = min(float(np.min(vmax[moving] / np.abs(delta[moving]))), max_path_speed)
    accel = float(np.min(amax[moving] / np.abs(delta[moving])))
    t_acc, t_cruise, v_peak = _scalar_profile(speed, accel)
    duration = 2.0 * t_acc + t_cruise
    n = max(2, math.ceil(duration / sample_period) + 1)
    times = np.linspace(0.0, duration, n)
    s = np.empty(n)
    ds = np.empty(n)
    for i, t in enumerate(times):
        if t < t_acc:
            s[i], ds[i] = 0.5 * accel * t * t, accel * t
        elif t < t_acc + t_cruise:
            s[i], ds[i] = 0.5 * accel * t_acc * t_acc + v_peak * (t - t_acc), v_peak
        else:
            r = max(0.0, duration - t)
            s[i], ds[i] = 1.0 - 0.5 * accel * r * r, accel * r
    s[-1], ds[-1] = 1.0, 0.0
    positions = q0[None, :] + s[:, None] * delta[None, :]
    velocities = ds[:, None] * delta[None, :]
    return JointMove(times, positions, velocities, duration)
