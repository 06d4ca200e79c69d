"""Closed-loop helpers for contact_control tests: a controller driving a perfectly tracking end effector."""

from __future__ import annotations

from collections import deque
from collections.abc import Callable, Sequence

import numpy as np
from contact_control.laws import AxisLaw

from contact_control import ContactControl, load_settings

DT = 0.002  # 500 Hz, the fork's cycle


def rot(axis: Sequence[float], angle: float) -> np.ndarray:
    """Rotation matrix about a unit axis (Rodrigues)."""
    a = np.asarray(axis, dtype=float)
    a = a / np.linalg.norm(a)
    k = np.array([[0, -a[2], a[1]], [a[2], 0, -a[0]], [-a[1], a[0], 0]])
    return np.eye(3) + np.sin(angle) * k + (1 - np.cos(angle)) * k @ k


def controller(**params: object) -> ContactControl:
    """A controller with the defaults, no start-up tare (tests control the bias), plus overrides."""
    return ContactControl(load_settings({"tare_on_startup": False, **params}))


def laws(**per_axis: AxisLaw) -> list[AxisLaw]:
    """Six laws, AxisLaw() (none) for every axis not named."""
    return [per_axis.get(name, AxisLaw()) for name in ("x", "y", "z", "rx", "ry", "rz")]


class ClosedLoop:
    """Integrates the commanded twist (control = fixed frame) into the EEF pose, as an ideal robot would.

    Args:
        lag: the arm follows each command this late [s] (a real arm's command-to-motion delay; 0: ideal).
    """

    def __init__(self, ctrl: ContactControl, pose: np.ndarray | None = None, lag: float = 0.0) -> None:
        self.ctrl = ctrl
        self.pose = np.eye(4) if pose is None else pose.copy()
        self.t = 0.0
        self.results: list = []
        self._pending: deque = deque([np.zeros(6)] * round(lag / DT))

    def start(self, axis_laws: Sequence[AxisLaw]) -> None:
        self.ctrl.set_laws(axis_laws, self.pose, self.t)

    def run(self, wrench: Callable[[float, np.ndarray], Sequence[float]] | Sequence[float], seconds: float):
        """Runs cycles with a wrench (constant, or a function of time and pose); returns the last result."""
        result = None
        for _ in range(round(seconds / DT)):
            w = wrench(self.t, self.pose) if callable(wrench) else wrench
            result = self.ctrl.update(w, self.t, eef_pose=self.pose)
            self.results.append(result)
            self._pending.append(np.asarray(result.velocity))
            v = self._pending.popleft()
            self.pose[:3, 3] += v[:3] * DT
            if np.any(v[3:]):
                angle = np.linalg.norm(v[3:]) * DT
                self.pose[:3, :3] = rot(v[3:], angle) @ self.pose[:3, :3]
            self.t += DT
        return result

    def velocities(self) -> np.ndarray:
        return np.array([r.velocity for r in self.results])
