"""Joint velocities for an arm with fewer than six joints: the tip's translation first, its rotation as far as
the remaining joints allow (jog_arm README, *Fewer than six joints*).

A 5-joint arm cannot follow every 6-D twist. The translation is solved first with the damped pseudo-inverse
of the Jacobian's linear rows, ``dq₁ = J_t⁺ v``; the rotation then uses only joint motions that leave the
translation unchanged (the null space ``N = I - J_t⁺ J_t``): ``dq = dq₁ + (J_r N)⁺ (ω - J_r dq₁)``. The
rotation axes ``J_r N`` cannot produce (its left singular vectors of zero singular value) are the directions
the tip cannot turn about while its position is kept: the status names them. No ROS here.
"""

from __future__ import annotations

import numpy as np
from compliant_common.typedefs import FloatArray

__all__ = ["PriorityTask"]

# A singular value of J_r N below this fraction of the largest (or below _ABSOLUTE) is a direction the arm
# cannot turn about: exactly zero up to rounding (1e-16) for a 5-joint arm, so any small threshold separates.
_RELATIVE = 1e-6
_ABSOLUTE = 1e-9


class PriorityTask:
    """Translation first, then rotation, for `nv` joints (3 to 5).

    Attributes:
        uncontrolled: Unit rotation axes (rows, the Jacobian's axes) the tip cannot turn about while its
            position is kept, at the configuration of the last :meth:`update`.
    """

    def __init__(self, nv: int) -> None:
        self._eye_n = np.eye(nv)
        self._eye3 = np.eye(3)
        self._translation: np.ndarray = np.zeros((nv, 3))  # J_t⁺ (damped)
        self._rotation: np.ndarray = np.zeros((nv, 3))  # (J_r N)⁺ (damped, truncated)
        self._jr: np.ndarray = np.zeros((3, nv))
        self.uncontrolled: FloatArray = np.zeros((0, 3))

    def update(self, J: FloatArray, damping2: float) -> None:
        """Factorises the task at the Jacobian `J` (6 x nv, linear rows first) with damping λ² `damping2`."""
        jt, jr = J[:3], J[3:]
        self._jr = jr
        pt = np.linalg.solve(jt @ jt.T + self._eye3 * damping2, jt).T  # J_tᵀ (J_t J_tᵀ + λ²I)⁻¹
        self._translation = pt
        u, s, vt = np.linalg.svd(jr @ (self._eye_n - pt @ jt), full_matrices=False)
        largest = float(s[0]) if s.size else 0.0
        keep = s > max(_RELATIVE * largest, _ABSOLUTE)
        gains = s[keep] / (s[keep] ** 2 + damping2)
        self._rotation = (vt[keep].T * gains) @ u[:, keep].T
        self.uncontrolled = u[:, ~keep].T  # u is 3 x 3 for 3 to 5 joints

    def solve(self, x: FloatArray) -> FloatArray:
        """dq for the twist `x` (linear rows first, weighted as the Jacobian was)."""
        dq1: FloatArray = self._translation @ x[:3]
        return dq1 + self._rotation @ (x[3:] - self._jr @ dq1)

