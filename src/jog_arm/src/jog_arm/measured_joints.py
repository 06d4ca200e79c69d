"""The measured joint state, and the two joint orders: the user's (`joint_names`) and the model's.

Every vector given to or returned by `JogCalcs` is in the user's order; the cycle works in the model's
(kinematic) order. Joint vectors are plain float lists: faster than numpy at 6-7 values.
"""

from __future__ import annotations

import math
import operator
from collections.abc import Sequence

import numpy as np
from compliant_common.typedefs import FloatArray

from jog_arm.kinematics import ArmModel

__all__ = ["MeasuredJoints"]


class MeasuredJoints:
    """The last measured joint positions (model order) and when they were received.

    Args:
        model: The arm model (its joint order, and which joints turn without limits).
        joint_names: The user's joint order (the model's joints).
    """

    def __init__(self, model: ArmModel, joint_names: tuple[str, ...]) -> None:
        self.nv = nv = model.nv
        self.joint_names = joint_names
        #: to_user[i]: model index of user joint i.
        self.to_user = np.array([model.joint_names.index(name) for name in joint_names], dtype=np.intp)
        self._to_user_list = self.to_user.tolist()
        self._identity_order = self._to_user_list == list(range(nv))
        # Continuous joints without position limits: whole turns apart is the same posture for them.
        self._turning = [
            i
            for i, continuous in enumerate(model.continuous)
            if continuous and math.isinf(model.lower[i]) and math.isinf(model.upper[i])
        ]
        #: The measured positions, model order (a new list per joint state); zeros before the first.
        self.positions = [0.0] * nv
        #: Whether a joint state was received.
        self.received = False
        #: Receive time [s] of the joint state; None: its age is not checked; -inf: wait for a fresh one.
        self.time: float | None = None
        self._names_cache: tuple[tuple[str, ...], list[int]] = ((), [])

    def set(self, positions: Sequence[float], now: float | None) -> None:
        """Stores positions in user order, received at `now` [s] (None: its age is not checked).

        Raises:
            ValueError: Wrong length or a non-finite value (the previous state is kept).
        """
        values = [float(v) for v in positions]
        if len(values) != self.nv or not all(math.isfinite(v) for v in values):
            raise ValueError(f"joint state must be {self.nv} finite positions for {list(self.joint_names)}")
        self._store(values, now)

    def set_named(self, names: Sequence[str], positions: Sequence[float], now: float | None) -> bool:
        """Stores a JointState-like (names, positions) pair; False, keeping the previous state, if a joint is
        missing or a value is not finite (extra joints are ignored)."""
        key = tuple(names)
        cached_names, index = self._names_cache
        if key != cached_names:  # a publisher's name list rarely changes: map it once
            lookup = {name: i for i, name in enumerate(key)}
            if any(name not in lookup for name in self.joint_names):
                return False
            index = [lookup[name] for name in self.joint_names]
            self._names_cache = (key, index)
        if len(positions) != len(key):
            return False
        values = [float(positions[i]) for i in index]
        if not all(math.isfinite(v) for v in values):
            return False
        self._store(values, now)
        return True

    def _store(self, values: list[float], now: float | None) -> None:
        self.time = now
        if self._identity_order:
            self.positions = values
        else:
            q = [0.0] * self.nv
            for user_index, model_index in enumerate(self._to_user_list):
                q[model_index] = values[user_index]
            self.positions = q
        self.received = True

    def clock_jumped(self) -> None:
        """The clock jumped: the state's age is unknown until the next one (if ages are checked)."""
        if self.time is not None:
            self.time = -math.inf

    def strays_from(self, q_ref: list[float], limit: float) -> bool:
        """Whether the measured positions are more than `limit` from `q_ref` (model order); 0: never."""
        q_meas = self.positions
        if limit > 0.0 and max(map(abs, map(operator.sub, q_meas, q_ref))) > limit:
            # A driver may wrap a continuous joint's angle while the command goes on unwrapped.
            return not self._turning or self._wrapped_error(q_meas, q_ref) > limit
        return False

    def _wrapped_error(self, q_meas: list[float], q_ref: list[float]) -> float:
        """Largest |measured - reference|, whole turns of the continuous joints taken out."""
        error = [abs(m - r) for m, r in zip(q_meas, q_ref, strict=True)]
        for i in self._turning:
            error[i] = abs(math.remainder(q_meas[i] - q_ref[i], math.tau))
        return max(error)

    def user_order(self, values: list[float]) -> tuple[float, ...]:
        """Model-order `values` as a user-order tuple."""
        if self._identity_order:
            return tuple(values)
        return tuple([values[i] for i in self._to_user_list])

    def model_order(self, values: Sequence[float]) -> FloatArray:
        """User-order `values` as a new model-order array."""
        q = np.empty(self.nv)
        q[self.to_user] = np.asarray(values, dtype=float)
        return q
