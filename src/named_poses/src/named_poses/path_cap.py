"""The collaborative speed cap on named-pose moves (no ROS): jog_arm's cap (the jog_arm README,
*Collaborative speed cap*) applied to the joint-space line a move follows, so a move to a named pose is no
faster toward a person than a jog. The node reads the region, payload and tip frame from jog_arm's
parameters, so one setting serves both.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from compliant_common.typedefs import FloatArray
from jog_arm.body_regions import OFF
from jog_arm.kinematics import ArmModel
from jog_arm.speed_cap import CapReading, SpeedCap, path_speed_limit

__all__ = ["PathCap"]


class PathCap:
    """The cap for moves of `joints` (the poses' order) with the tip at frame `tip`.

    Raises:
        jog_arm.kinematics.KinematicsError: `tip` is no frame of `urdf` moved by `joints`.
    """

    def __init__(self, urdf: str, joints: Sequence[str], tip: str) -> None:
        self.tip = tip
        self._model = ArmModel(urdf, tip, list(joints))
        self._order = [list(joints).index(name) for name in self._model.joint_names]
        self._cap = SpeedCap(self._model, 1.0, OFF, 0.0)

    def limit(self, region: str, payload: float, start: Sequence[float] | FloatArray,
              goal: Sequence[float] | FloatArray) -> CapReading:
        """The largest ds/dt of the move from `start` to `goal` (poses' order) within the cap for `region`
        with `payload` [kg] (inf: off), and the effective mass where it binds.

        Raises:
            ValueError: an unknown region (naming the known ones).
        """
        self._cap.configure(region, payload)
        q0 = np.asarray(start, dtype=float)[self._order]
        delta = np.asarray(goal, dtype=float)[self._order] - q0
        return path_speed_limit(self._cap, self._model, q0, delta)
