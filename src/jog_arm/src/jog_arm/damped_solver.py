"""Joint velocities for a tip twist: damped least squares on the tip Jacobian, with the singularity handling.

The Jacobian's linear rows are divided by ``singularity_length_scale`` so metres and radians weigh alike
(twists given to this module are weighted the same way). Its singular values come from the eigenvalues of
the 6x6 ``J·Jᵀ`` (eigenpy, a few µs); the condition number is the largest over the smallest (valid for 6 and
7 joints, unlike the fork's eigenvalues of J itself). The damped pseudo-inverse ``J⁺ = Jᵀ(JJᵀ + λ²I)⁻¹`` is
applied by a Cholesky solve, its λ growing as the smallest singular value falls. An arm with fewer than six
joints cannot follow every twist: its singular values come from the n x n ``Jᵀ·J`` and the twist is solved
translation first (`task_priority`).
"""

from __future__ import annotations

import math

import eigenpy
import numpy as np
from compliant_common.typedefs import FloatArray

from jog_arm.kinematics import ArmModel
from jog_arm.limits import singularity_scale
from jog_arm.settings import JogSettings
from jog_arm.task_priority import PriorityTask

__all__ = ["DampedSolver", "Geometry"]

# Joint-space step [rad, max-norm] of the finite difference that predicts the condition number.
_PREDICTION_STEP = 1e-3
_EIGENVALUES_ONLY = eigenpy.DecompositionOptions.EigenvaluesOnly
# Smallest damping λ² added once damping starts, so J·Jᵀ + λ²I stays invertible at an exact singularity.
_DAMPING_FLOOR = 1e-12
# [rad] a joint step above this per period bends the tip's path enough to straighten (see `straighten`)
_STRAIGHTEN_STEP = 1e-3
_STRAIGHTEN_LIMIT = 0.1  # a correction above this fraction of the velocity is not applied
# Damping μ² of the pulled joints' own task (S N Sᵀ + μ²I)⁻¹: where they take less than this share of the
# self-motion they get a fraction of the pull, and the other joints never move more than 1 / (2 μ) = 2.2
# times the pull's speed for them (a rail's share under an arm: 0.009-0.1, less the further it reaches).
_PULL_DAMPING2 = 0.05


class Geometry:
    """What a cycle needs that does not depend on the twist, at configuration `q` (see
    :meth:`DampedSolver.geometry`): the weighted Jacobian `J` and its condition number."""

    __slots__ = ("J", "condition", "q", "q_arr", "valid")

    def __init__(self) -> None:
        self.valid = False
        self.q: list[float] = []
        self.q_arr: FloatArray = np.zeros(0)
        self.J: FloatArray = np.zeros((6, 0))
        self.condition = math.inf


class DampedSolver:
    """The damped pseudo-inverse of one arm's tip Jacobian, and on a redundant arm the null-space pull
    toward a posture. Arrays are in model joint order; the factorisation is reused while the reference
    configuration does not change.

    Args:
        model: The arm model (its data is shared with the caller: see :meth:`invalidate`).
        settings: Validated parameters.
        posture: The null-space posture (model order), None: the configuration where motion starts.
        pulled: 1 for each joint (model order) the pull moves toward the posture, 0 for one it leaves to the
            self-motion; None: every joint.
    """

    def __init__(self, model: ArmModel, settings: JogSettings, posture: FloatArray | None,
                 pulled: FloatArray | None = None) -> None:
        self._model = model
        n = model.nv
        self._period = settings.pub_period
        # With publish_on_command a step lasts until the next twist, not pub_period: nothing to straighten.
        self._straighten_step = math.inf if settings.publish_on_command else _STRAIGHTEN_STEP
        self.retune(settings)
        self._posture_fixed = posture is not None
        # The pulled joints' indices and the identity of their task's size (None: every joint, projected).
        self._pulled: tuple[np.ndarray, FloatArray] | None = None
        if pulled is not None:
            idx = np.flatnonzero(pulled)
            self._pulled = (idx, np.eye(idx.size))
        # Per joint gain (0 for a joint not pulled) and gain x posture: the pull gain·(posture - q) costs
        # two vector operations per cycle.
        self._ns_gain = settings.nullspace_gain * (np.ones(n) if pulled is None else pulled)
        self._gain_posture = self._ns_gain * (np.zeros(n) if posture is None else posture)
        self._redundant = n > 6 and settings.nullspace_gain > 0.0
        self._inv_length = 1.0 / settings.singularity_length_scale
        #: Fewer than six joints: the twist is solved translation first (None: 6 or more, J⁺ by Cholesky).
        self.task = PriorityTask(n) if n < 6 else None
        m = min(n, 6)  # the size of J·Jᵀ (Jᵀ·J with fewer than six joints)
        self._jjt = np.zeros((m, m))
        self._displacement = np.zeros(6)
        self._eig = eigenpy.SelfAdjointEigenSolver(m)
        self._llt = eigenpy.LLT(m)
        self._eye6 = np.eye(m)
        self._eig_only = eigenpy.SelfAdjointEigenSolver(m)
        #: The reference configuration of the last :meth:`geometry` (Pinocchio reads it; zeros before).
        self.q_arr = np.zeros(n)
        self._geom = Geometry()

    def retune(self, settings: JogSettings) -> None:
        """Live tuning: the singularity thresholds and the pseudo-inverse's damping (from the next cycle)."""
        self._threshold = settings.singularity_threshold
        self._hard_stop = settings.hard_stop_singularity_threshold
        self._damping2 = settings.pinv_damping**2
        self._damping_threshold = settings.pinv_damping_threshold

    def start_motion(self, q_arr: FloatArray) -> None:
        """Motion starts at `q_arr`: without a configured posture, the null space pulls back toward it."""
        if not self._posture_fixed:
            np.multiply(q_arr, self._ns_gain, out=self._gain_posture)

    def invalidate(self) -> None:
        """The model's data was moved elsewhere: the next :meth:`geometry` recomputes."""
        self._geom.valid = False

    def geometry(self, q_ref: list[float]) -> Geometry:
        """The twist-independent part of a cycle at `q_ref` (Jacobian, condition number, factorised damped
        J·Jᵀ), reused while `q_ref` does not change (a shared object).

        Also leaves the placements of the tip's chain at `q_ref` in the model's data (see ArmModel.jacobian);
        whatever else moves the data must call :meth:`invalidate`.
        """
        g = self._geom
        if g.valid and g.q == q_ref:
            return g
        q_arr = self.q_arr
        q_arr[:] = q_ref
        # The eigenvalues of J·Jᵀ are the squared singular values (eigenpy: ~2 µs).
        J = self._model.jacobian(q_arr)
        J[:3] *= self._inv_length
        task = self.task
        A = np.dot(J, J.T, out=self._jjt) if task is None else np.dot(J.T, J, out=self._jjt)
        self._eig.compute(A, _EIGENVALUES_ONLY)
        sigma2 = self._eig.eigenvalues()  # ascending; a view, valid until the next compute
        s2_min, s2_max = float(sigma2[0]), float(sigma2[-1])
        # Damped pseudo-inverse J⁺ = Jᵀ(JJᵀ + λ²I)⁻¹: λ grows as the smallest singular value falls.
        s_min = math.sqrt(max(s2_min, 0.0))
        damping2 = 0.0
        if s_min < self._damping_threshold:
            ratio = s_min / self._damping_threshold
            damping2 = self._damping2 * (1.0 - ratio * ratio) + _DAMPING_FLOOR
            A += self._eye6 * damping2
        if task is not None:  # its own factorisation; the Cholesky one below is J⁺'s
            task.update(J, damping2)
        else:
            llt = self._llt
            llt.compute(A)
            if llt.info() != eigenpy.ComputationInfo.Success:  # numerically singular: damp harder
                A += self._eye6 * (_DAMPING_FLOOR + 1e-6 * s2_max)
                llt.compute(A)
        g.q = list(q_ref)
        g.q_arr, g.J = q_arr, J
        g.condition = math.sqrt(s2_max / s2_min) if s2_min > 0.0 else math.inf
        g.valid = True
        return g

    def solve(self, J: FloatArray, x: FloatArray, q_arr: FloatArray, scale: float) -> FloatArray:
        """dq = J⁺x with the J⁺ of the last :meth:`geometry` (whose `J` this is); on a redundant arm plus
        the null-space pull toward the posture, scaled by `scale`:
        J⁺x + (I - J⁺J)·pull = J⁺(x - J·pull) + pull."""
        if self.task is not None:
            return self.task.solve(x)
        llt = self._llt
        if not self._redundant:
            solved: FloatArray = llt.solve(x)  # eigenpy: untyped
            return J.T @ solved
        pull = (self._gain_posture - self._ns_gain * q_arr) * scale
        if self._pulled is not None:
            return self._pull_some(J, x, pull, *self._pulled)
        solved = llt.solve(x - J @ pull)
        dq_arr = J.T @ solved
        dq_arr += pull
        return dq_arr

    def _pull_some(self, J: FloatArray, x: FloatArray, pull: FloatArray, idx: np.ndarray, eye: FloatArray
                   ) -> FloatArray:
        """dq = J⁺x + N Sᵀ(S N Sᵀ + μ²I)⁻¹(S·pull - S J⁺x): the pulled joints S (a rail) move at their pull
        as far as the self-motion N = I - J⁺J lets them, the others as the self-motion needs (a secondary
        task of its own, not the pull projected: that moves a rail at its small share of the self-motion)."""
        llt = self._llt
        dq: FloatArray = J.T @ llt.solve(x)
        # N Sᵀ = Sᵀ - J⁺J Sᵀ (n x k)
        ns: FloatArray = -(J.T @ np.reshape(llt.solve(J[:, idx]), (J.shape[0], idx.size)))
        ns[idx, np.arange(idx.size)] += 1.0
        wanted: FloatArray = pull[idx] - dq[idx]
        step: FloatArray = np.linalg.solve(ns[idx] + _PULL_DAMPING2 * eye, wanted)
        dq += ns @ step
        return dq

    def singularity_slowdown(self, g: Geometry, x: FloatArray) -> float:
        """Speed scale for the weighted root-axes twist `x` at `g`: below 1 only if the condition number
        grows along the joint motion for `x` (predicted by a finite difference), so backing out is never
        slowed. Past the threshold this moves the model's data (`g` is then recomputed when next asked)."""
        condition = g.condition
        if condition > self._threshold:
            q_arr = g.q_arr
            toward = self._predicted_condition(q_arr, self.solve(g.J, x, q_arr, 1.0)) > condition
            return singularity_scale(condition, self._threshold, self._hard_stop, toward)
        return 1.0

    def _predicted_condition(self, q: FloatArray, dq: FloatArray) -> float:
        """Condition number a small step along `dq` would give (overwrites the model's data)."""
        norm = max(map(abs, dq.tolist()))
        if norm == 0.0:
            return 0.0
        self._geom.valid = False
        J = self._model.jacobian(q + dq * (_PREDICTION_STEP / norm))  # a fresh array
        J[:3] *= self._inv_length
        self._eig_only.compute(J @ J.T if self.task is None else J.T @ J, _EIGENVALUES_ONLY)
        sigma2 = self._eig_only.eigenvalues()
        return math.sqrt(float(sigma2[-1]) / float(sigma2[0])) if sigma2[0] > 0.0 else math.inf

    def straighten(self, q_ref: list[float], dq: list[float]) -> list[float]:
        """The joint velocity whose straight step over the period ends where the twist J(q_ref)·dq, held that
        long, takes the tip: a straight step in joint space moves the tip on a curve (at 20 Hz a 7-joint
        follower drifted 3.6 mm sideways over 15 cm). One Newton step with the damped pseudo-inverse at
        `q_ref`; a correction of second order (a few percent of the step), before the limits. Steps of at
        most 1 mrad per period are returned as they are."""
        period = self._period
        if max(map(abs, dq)) * period <= self._straighten_step:
            return dq
        g = self.geometry(q_ref)
        dq_arr = np.asarray(dq)
        q_end = g.q_arr + dq_arr * period
        error = self._model.tip_displacement(g.q_arr, q_end, self._displacement)
        error[:3] *= self._inv_length
        error -= g.J @ dq_arr * period
        task = self.task
        correction = (g.J.T @ self._llt.solve(error) if task is None else task.solve(error)) / period
        if np.max(np.abs(correction)) > _STRAIGHTEN_LIMIT * np.max(np.abs(dq_arr)):
            return dq  # not second order: a step too long for one Newton step to be right
        dq_arr -= correction
        straightened: list[float] = dq_arr.tolist()
        return straightened
