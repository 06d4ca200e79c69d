"""Speed scaling for singularities and joint limits. Every limit scales the WHOLE joint velocity vector.

Scaling the vector (never clipping one joint) keeps the direction of the commanded Cartesian motion, so
the end effector slows down along its path instead of veering off it.

The per-joint work runs on plain Python floats: for 6 or 7 joints that is several times faster than
numpy, whose per-call overhead dominates on vectors this short.
"""

from __future__ import annotations

import math
import operator
from collections.abc import Sequence

import numpy as np
from compliant_common.typedefs import FloatArray

__all__ = ["JointLimiter", "singularity_scale"]

# A joint this close to its stop [rad] counts as being at it (the ramp approaches it exponentially).
AT_STOP = 1e-5


def singularity_scale(condition: float, threshold: float, hard_stop: float, toward: bool) -> float:
    """Speed scale for the Jacobian's condition number, as the fork and MoveIt Servo do.

    Args:
        condition: Condition number (largest / smallest singular value).
        threshold: Condition number where slowing starts (`singularity_threshold`).
        hard_stop: Condition number where motion stops (`hard_stop_singularity_threshold`).
        toward: Whether the commanded motion increases the condition number. Motion away is never
            scaled, so the arm can always back out.

    Returns:
        1 below `threshold` or when moving away, 0 at or beyond `hard_stop`, linear in between.
    """
    if not toward or condition <= threshold:
        return 1.0
    if condition >= hard_stop:
        return 0.0
    return 1.0 - (condition - threshold) / (hard_stop - threshold)


class JointLimiter:
    """Joint position, velocity and acceleration limits of one arm.

    A joint without position limits (a continuous joint: lower -inf and upper +inf) is skipped by the
    position checks; its velocity and acceleration limits apply as for any joint.

    Args:
        lower: Lower position limits [rad] (-inf: none).
        upper: Upper position limits [rad] (+inf: none).
        max_velocity: Velocity limits [rad/s].
        max_acceleration: Acceleration limits [rad/s²].
        margin: Distance [rad, m] kept from each position limit: one for all joints, or one per joint.
        slowdown_width: Width [rad, m] of the zone before the margin where the allowed speed toward the
            limit falls linearly from the velocity limit to zero (0 = no ramp, braking only); one for all
            joints or one per joint.
        period: Control period [s].
        brake_scale: The multiple of `max_acceleration` a stop asked for with `limit(..., brake=True)` may
            decelerate at.
    """

    def __init__(
        self,
        lower: Sequence[float] | FloatArray,
        upper: Sequence[float] | FloatArray,
        max_velocity: Sequence[float] | FloatArray,
        max_acceleration: Sequence[float] | FloatArray,
        margin: float | Sequence[float],
        slowdown_width: float | Sequence[float],
        period: float,
        brake_scale: float = 1.0,
    ) -> None:
        self.lower_stop = np.asarray(lower, dtype=float) + np.asarray(margin, dtype=float)
        self.upper_stop = np.asarray(upper, dtype=float) - np.asarray(margin, dtype=float)
        self.max_velocity = np.array(max_velocity, dtype=float)
        self.max_acceleration = np.array(max_acceleration, dtype=float)
        self.period = float(period)
        self._lo = self.lower_stop.tolist()
        self._hi = self.upper_stop.tolist()
        self._inv_v = (1.0 / self.max_velocity).tolist()
        self._step = (self.max_acceleration * self.period).tolist()  # largest velocity change per cycle
        self._brake_step = (self.max_acceleration * self.period * brake_scale).tolist()
        self._two_a = (2.0 * self.max_acceleration).tolist()
        width = np.broadcast_to(np.asarray(slowdown_width, dtype=float), self.max_velocity.shape)
        self._ramp = [float(v / w) if w > 0.0 else math.inf
                      for v, w in zip(self.max_velocity, width, strict=True)]
        self._inv_period = 1.0 / self.period
        # Position checks loop over the joints with at least one finite stop only, with their constants.
        self._bounded = [
            (i, lo, hi, step, two_a, ramp)
            for i, (lo, hi, step, two_a, ramp) in enumerate(
                zip(self._lo, self._hi, self._step, self._two_a, self._ramp, strict=True)
            )
            if math.isfinite(lo) or math.isfinite(hi)
        ]

    def position_scale(self, q: Sequence[float], dq: Sequence[float]) -> float:
        """Scale for `dq` so no joint runs into its position limit (minus the margin).

        The allowed speed of a joint toward its stop is the smallest of: the velocity limit ramped down
        over the slow-down zone, the speed from which the acceleration limit can still stop before the
        stop, and the distance it covers in one period. The braking curve ``v²/2a + v·dt <= d`` bounds the
        distance of a stop in steps of ``a·dt`` per cycle (the continuous ``v²/2a`` falls short by up to
        ``v·dt/2 + a·dt²/8``, enough to overrun the margin).
        Joints moving away from a stop, or still, and joints without stops are never limited.

        Args:
            q: Joint positions the motion starts from [rad].
            dq: Joint velocities [rad/s].

        Returns:
            Scale in [0, 1]; 0 if a joint moving toward its stop is already at it.
        """
        scale = 1.0
        for i, lo, hi, step, two_a, ramp in self._bounded:
            vi = dq[i]
            qi = q[i]
            if vi > 0.0:
                d = hi - qi
            elif vi < 0.0:
                d = qi - lo
                vi = -vi
            else:
                continue
            if d <= AT_STOP:
                return 0.0
            cap = min(math.sqrt(step * step + two_a * d) - step, ramp * d, d * self._inv_period)
            if cap < vi * scale:
                scale = cap / vi
        return scale

    def velocity_scale(self, dq: Sequence[float]) -> float:
        """Scale in (0, 1] that brings every joint within its velocity limit."""
        worst = max(map(operator.mul, map(abs, dq), self._inv_v))
        return 1.0 if worst <= 1.0 else 1.0 / worst

    def limit_acceleration(
        self, previous: Sequence[float], target: Sequence[float], brake: bool = False
    ) -> tuple[list[float], bool]:
        """Moves from `previous` toward `target` by the largest step within the acceleration limits.

        The whole change vector is scaled, so a stop or a start keeps the direction of motion.

        Args:
            previous: Last output velocities [rad/s].
            target: Wanted velocities [rad/s].
            brake: A stop: the limits times `brake_scale`.

        Returns:
            The new velocities and whether the step was limited.
        """
        k = 1.0
        for p, t, step in zip(previous, target, self._brake_step if brake else self._step, strict=True):
            change = abs(t - p)
            if change * k > step:
                k = step / change
        if k >= 1.0:
            return list(target), False
        return [p + k * (t - p) for p, t in zip(previous, target, strict=True)], True

    def limit(
        self, q: Sequence[float], dq: list[float], previous: Sequence[float], settle: bool,
        brake: bool = False,
    ) -> tuple[list[float], float, float]:
        """Position, velocity, then acceleration limits for `dq` from `q`, each scaling the whole vector.

        Args:
            q: Joint positions the motion starts from [rad].
            dq: Wanted joint velocities [rad/s].
            previous: Last output velocities [rad/s].
            settle: Nothing is being followed: a result within 1e-9 rad/s of rest is made exactly zero, so
                the stop ends.
            brake: A stop (a contact): decelerate at `brake_scale` times the acceleration limits.

        Returns:
            The new velocities (a new list), the position scale and the velocity scale.
        """
        s_pos = self.position_scale(q, dq)
        s_vel = self.velocity_scale(dq) if s_pos == 1.0 else self.velocity_scale([v * s_pos for v in dq])
        scale = s_pos * s_vel
        if scale < 1.0:
            dq = [v * scale for v in dq]
        dq_new, limited = self.limit_acceleration(previous, dq, brake)
        if limited:  # slowing down slower than asked might cross a stop: position beats acceleration
            guard = self.step_scale(q, dq_new)
            if guard < 1.0:
                dq_new = [v * guard for v in dq_new]
        if settle and max(map(abs, dq_new)) < 1e-9:
            dq_new = [0.0] * len(dq_new)
        return dq_new, s_pos, s_vel

    def step_scale(self, q: Sequence[float], dq: Sequence[float]) -> float:
        """Scale for `dq` so ``q + dq·period`` crosses no stop a joint moves toward (the last guard)."""
        scale = 1.0
        period = self.period
        for i, lo, hi, _, _, _ in self._bounded:
            vi = dq[i]
            qi = q[i]
            if vi > 0.0:
                room = max(hi - qi, 0.0)
                if vi * period * scale > room:
                    scale = room / (vi * period)
            elif vi < 0.0:
                room = max(qi - lo, 0.0)
                if -vi * period * scale > room:
                    scale = room / (-vi * period)
        return scale

    def within_stops(self, q: Sequence[float]) -> bool:
        """True if every joint is inside its limits minus the margin (joints without stops always are)."""
        return all(lo <= q[i] <= hi for i, lo, hi, _, _, _ in self._bounded)
