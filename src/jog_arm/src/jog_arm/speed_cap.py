"""The collaborative speed cap (the package README, *Collaborative speed cap*): the tip's speed in the
direction it is commanded to move, at most what ISO/TS 15066 permits toward the configured body region
(`body_regions.max_speed`) for the arm's effective mass in that direction plus the payload.

The arm's effective mass along a unit direction u at the tip is m_R(u) = 1 / (u^T J_v M^-1 J_v^T u), with
J_v the tip Jacobian's linear rows and M the joint-space inertia from the URDF (Pinocchio); the payload (the
tool and what it carries, a point mass at the tip) adds to it. The twist is scaled as a whole, so its
direction and its rotation-to-translation ratio stay. No ROS here.
"""

from __future__ import annotations

import math
from operator import sub
from typing import NamedTuple

import numpy as np
import pinocchio as pin
from compliant_common.typedefs import FloatArray

from jog_arm.body_regions import OFF, BodyRegion, max_speed, region_named
from jog_arm.kinematics import ArmModel

__all__ = ["CapReading", "SpeedCap", "path_speed_limit"]


class CapReading(NamedTuple):
    """The cap along the last commanded direction (inf: off, or no translation commanded)."""

    speed: float  # [m/s]
    robot_mass: float  # the arm's effective mass in that direction plus the payload [kg]


_NONE = CapReading(math.inf, math.nan)
# [rad or m] every joint closer than this to where the inverse mass was computed: reused. The cap then
# changes by under 0.2 % (a 6- and a 7-joint cobot, 300 random poses and directions each:
# tests/jog_arm/test_jog_arm_speed_cap.py).
_REUSE_WITHIN = 0.01


class SpeedCap:
    """The cap for one arm; `scale` is called once per cycle that follows a twist.

    Args:
        model: the arm (its own Pinocchio data is used here: the cycle's is left alone).
        length_scale: the factor the weighted Jacobian's and twist's linear parts were divided by
            (`singularity_length_scale`).
        region: a `body_regions.REGIONS` name, or "off".
        payload: [kg] added to the arm's effective mass in every direction.
    """

    def __init__(self, model: ArmModel, length_scale: float, region: str, payload: float) -> None:
        self._model = model
        self._data = model.model.createData()
        self._q_pin = pin.neutral(model.model)
        self._length = length_scale
        self._length2 = length_scale * length_scale
        self._q: list[float] | None = None
        self._inverse = [[0.0] * 3 for _ in range(3)]  # J_v M^-1 J_v^T at _q
        self._lower = np.tril_indices(model.nv, -1)
        self._jm, self._jmj = np.zeros((3, model.nv)), np.zeros((3, 3))
        # Some Pinocchio versions fill M^-1's upper half only.
        probe = pin.computeMinverse(model.model, self._data, self._q_pin)
        self._upper_only = not np.allclose(probe, probe.T)
        self.region: BodyRegion | None = None
        self.payload = 0.0
        self.last = _NONE
        self.configure(region, payload)

    def configure(self, region: str, payload: float) -> None:
        """A new region ("off": no cap) and payload [kg]; ValueError for an unknown region (nothing
        changes)."""
        self.region = None if region == OFF else region_named(region)
        self.payload = float(payload)
        self.last = _NONE
        self._q = None

    def robot_mass(self, q: list[float], J: FloatArray, direction: FloatArray) -> float:
        """The arm's effective mass along `direction` (3, root axes, any length > 0) at `q` plus the
        payload [kg]; `J` is the weighted tip Jacobian at `q` (`DampedSolver.geometry`)."""
        self.prepare(q, J)
        (a, b, c), (_, d, e), (_, _, f) = self._inverse
        x, y, z = float(direction[0]), float(direction[1]), float(direction[2])
        along = (a * x * x + d * y * y + f * z * z + 2.0 * (b * x * y + c * x * z + e * y * z)) / (
            x * x + y * y + z * z)
        return (1.0 / along if along > 0.0 else math.inf) + self.payload

    def prepare(self, q: list[float], J: FloatArray) -> None:
        """J_v M^-1 J_v^T at `q`, again once a joint has moved `_REUSE_WITHIN` from where it was last
        computed (JogCalcs.prefetch calls it off the command's path); the rest of a cycle's work is on plain
        floats, where numpy's per-call overhead dominates."""
        last = self._q
        if self.region is None or (last is not None and max(map(abs, map(sub, q, last))) < _REUSE_WITHIN):
            return
        model = self._model
        q_pin = model.pin_q(np.asarray(q, dtype=float), self._q_pin)
        inverse_mass = pin.computeMinverse(model.model, self._data, q_pin)
        if self._upper_only:
            inverse_mass[self._lower] = inverse_mass.T[self._lower]
        np.dot(J[:3], inverse_mass, out=self._jm)
        np.dot(self._jm, J[:3].T, out=self._jmj)
        self._jmj *= self._length2
        self._inverse = self._jmj.tolist()
        self._q = list(q)

    def scale(self, q: list[float], J: FloatArray, twist: FloatArray, factor: float = 1.0) -> float:
        """The factor (<= 1) that brings `twist` x `factor` (root axes, weighted like `J`) to the cap in its
        direction; `last` holds the cap."""
        region = self.region
        if region is None:
            return 1.0
        x, y, z = float(twist[0]), float(twist[1]), float(twist[2])
        speed = math.sqrt(x * x + y * y + z * z) * self._length * factor  # [m/s]
        if speed == 0.0:
            self.last = _NONE
            return 1.0
        mass = self.robot_mass(q, J, twist)
        cap = max_speed(region, mass)
        self.last = CapReading(cap, mass)
        return min(1.0, cap / speed)


def path_speed_limit(cap: SpeedCap, model: ArmModel, start: FloatArray, delta: FloatArray,
                     samples: int = 100) -> CapReading:
    """The cap on a joint-space line q(s) = `start` + s `delta` (model order), s in [0, 1]: the largest
    ds/dt that keeps the tip within the cap at every sample (`speed`, inf: off or the tip does not
    translate), and the effective mass where it binds. `cap` is made with length scale 1 (plain Jacobian)."""
    region, best = cap.region, _NONE
    if region is None:
        return best
    for s in np.linspace(0.0, 1.0, samples):
        q = start + s * delta
        J = model.jacobian(q)
        v = J[:3] @ delta  # the tip's velocity per unit ds/dt
        speed = math.sqrt(float(v @ v))
        if speed < 1e-9:
            continue
        mass = cap.robot_mass(q.tolist(), J, v)
        allowed = max_speed(region, mass) / speed
        if allowed < best.speed:
            best = CapReading(allowed, mass)
    return best
