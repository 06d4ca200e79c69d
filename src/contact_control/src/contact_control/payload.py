"""Payload identification: the tool's mass and centre of mass and the sensor's bias from static wrenches.

The model is the one the preprocessor compensates with (see `WrenchPreprocessor.gravity_wrench`): at rest,
with nothing touching the tool, a sensor whose orientation puts gravity at u = R_world_sensor^T g (sensor
frame) reads

    F = m u + b_F,        T = c x (m u) + b_T = -[u]x (m c) + b_T

Both are linear in the unknowns, so two small least-squares problems give (m, b_F) and (m c, b_T); with
samples at 3 or more orientations whose gravity directions do not lie on one line through the others (the
differences between them must span a plane; 6+ samples tilted about two axes are better), both are well
posed. The residuals say how well the model fits (contact, cable drag, a moving arm show up there),
the condition numbers how well the orientations pin the unknowns down.
"""

from __future__ import annotations

import csv
import math
from collections.abc import Iterable, Sequence
from dataclasses import dataclass

import numpy as np
from compliant_common.errors import StackError
from compliant_common.typedefs import FloatArray

__all__ = ["PayloadError", "PayloadFit", "fit_payload", "gravity_in_sensor", "read_csv_samples"]

MAX_CONDITION = 1e3  # beyond this the orientations are too alike to separate mass, COM and bias


class PayloadError(StackError):
    """Too few or too similar samples, or unreadable data."""


@dataclass(frozen=True)
class PayloadFit:
    """The identified payload.

    Attributes:
        mass: [kg].
        com: Centre of mass in the sensor frame [m].
        bias: Force [N] and torque [Nm] offset of the sensor (its reading with no tool), sensor frame.
        force_rms, torque_rms: RMS residual of the fit [N], [Nm].
        condition: The larger condition number of the two least-squares problems.
        samples: How many samples went in.
    """

    mass: float
    com: tuple[float, float, float]
    bias: tuple[float, ...]
    force_rms: float
    torque_rms: float
    condition: float
    samples: int

    def yaml_keys(self) -> str:
        """The contact_control parameters, as lines to paste into the robot's contact_control YAML."""
        com = ", ".join(f"{c:.4f}" for c in self.com)
        bias = ", ".join(f"{b:.4f}" for b in self.bias)
        return f"tool_mass: {self.mass:.4f}\ntool_com: [{com}]\nbias: [{bias}]\n"

    def describe(self) -> str:
        com = ", ".join(f"{c * 1e3:.1f}" for c in self.com)
        return (
            f"mass {self.mass:.4f} kg, centre of mass ({com}) mm in the sensor frame, from {self.samples} "
            f"samples; residuals {self.force_rms:.3f} N, {self.torque_rms:.4f} Nm rms; condition "
            f"{self.condition:.1f}"
        )


def gravity_in_sensor(
    R_world_sensor: Sequence[Sequence[float]], gravity: Sequence[float] = (0.0, 0.0, -9.81)
) -> tuple[float, float, float]:
    """Gravity [m/s^2] in the sensor frame: R^T g."""
    r = np.asarray(R_world_sensor, dtype=float)
    return tuple((r.T @ np.asarray(gravity, dtype=float)).tolist())


def _skew(u: FloatArray) -> FloatArray:
    return np.array([[0.0, -u[2], u[1]], [u[2], 0.0, -u[0]], [-u[1], u[0], 0.0]])


def fit_payload(samples: Iterable[tuple[Sequence[float], Sequence[float]]]) -> PayloadFit:
    """Least-squares payload from (gravity in the sensor frame [m/s^2], wrench [N, Nm]) pairs, one per static
    orientation (average many readings per orientation first: the noise then averages out).

    Raises:
        PayloadError: fewer than 3 samples, non-finite values, or orientations too alike (the message says
            which part is ill-posed).
    """
    rows = [(np.asarray(u, dtype=float), np.asarray(w, dtype=float)) for u, w in samples]
    if len(rows) < 3:
        raise PayloadError(f"need samples at 3 or more orientations (6+ is better), got {len(rows)}")
    for u, w in rows:
        if u.shape != (3,) or w.shape != (6,) or not (np.all(np.isfinite(u)) and np.all(np.isfinite(w))):
            raise PayloadError("each sample needs a finite gravity 3-vector and a finite wrench 6-vector")
    n = len(rows)
    eye = np.eye(3)
    A_f = np.zeros((3 * n, 4))
    A_t = np.zeros((3 * n, 6))
    y_f = np.zeros(3 * n)
    y_t = np.zeros(3 * n)
    for k, (u, w) in enumerate(rows):
        s = slice(3 * k, 3 * k + 3)
        A_f[s, 0], A_f[s, 1:] = u, eye
        A_t[s, :3], A_t[s, 3:] = -_skew(u), eye
        y_f[s], y_t[s] = w[:3], w[3:]
    cond_f, cond_t = np.linalg.cond(A_f), np.linalg.cond(A_t)
    if not cond_f < MAX_CONDITION:
        raise PayloadError(f"the orientations do not separate mass from force bias (condition {cond_f:.3g})")
    if not cond_t < MAX_CONDITION:
        raise PayloadError(
            f"the orientations are too alike: the centre of mass is not observable (condition {cond_t:.3g}); "
            "add samples tilted about another axis"
        )
    x_f = np.linalg.lstsq(A_f, y_f, rcond=None)[0]
    x_t = np.linalg.lstsq(A_t, y_t, rcond=None)[0]
    mass = float(x_f[0])
    if not mass > 1e-6:
        raise PayloadError(f"fitted mass {mass:.4g} kg is not positive: does the sensor read the other sign?")
    com = tuple((x_t[:3] / mass).tolist())
    return PayloadFit(
        mass=mass,
        com=com,
        bias=tuple(x_f[1:].tolist()) + tuple(x_t[3:].tolist()),
        force_rms=float(math.sqrt(np.mean((A_f @ x_f - y_f) ** 2))),
        torque_rms=float(math.sqrt(np.mean((A_t @ x_t - y_t) ** 2))),
        condition=float(max(cond_f, cond_t)),
        samples=n,
    )


def read_csv_samples(
    path: str, gravity: Sequence[float] = (0.0, 0.0, -9.81)
) -> list[tuple[tuple[float, float, float], tuple[float, ...]]]:
    """Samples from a CSV with columns fx, fy, fz, tx, ty, tz and either r11..r33 (R_world_sensor, rows) or
    gx, gy, gz (gravity, pointing down, in the sensor frame [m/s^2]; an accelerometer at rest reads its
    negative), one row per orientation.

    Raises:
        PayloadError: missing columns or non-numbers (naming them).
    """
    wrench_cols = ("fx", "fy", "fz", "tx", "ty", "tz")
    rot_cols = tuple(f"r{i}{j}" for i in (1, 2, 3) for j in (1, 2, 3))
    with open(path, newline="") as handle:
        reader = csv.DictReader(handle, skipinitialspace=True)
        fields = {name.strip() for name in reader.fieldnames or ()}
        missing = [c for c in wrench_cols if c not in fields]
        if missing:
            raise PayloadError(f"{path}: no column(s) {missing} (need fx..tz)")
        use_gravity = {"gx", "gy", "gz"} <= fields
        if not use_gravity and not set(rot_cols) <= fields:
            raise PayloadError(f"{path}: need gx, gy, gz or r11..r33 columns for each row's orientation")
        samples = []
        for line, row in enumerate(reader, start=2):
            row = {k.strip(): v for k, v in row.items() if k}
            try:
                w = tuple(float(row[c]) for c in wrench_cols)
                if use_gravity:
                    u = (float(row["gx"]), float(row["gy"]), float(row["gz"]))
                else:
                    r = [float(row[c]) for c in rot_cols]
                    u = gravity_in_sensor([r[0:3], r[3:6], r[6:9]], gravity)
            except (TypeError, ValueError) as err:
                raise PayloadError(f"{path}:{line}: {err}") from err
            samples.append((u, w))
    return samples
