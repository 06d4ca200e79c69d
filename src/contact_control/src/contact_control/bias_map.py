"""The sensor's offset as a function of the pose: fitted from a calibration sweep, predicted every cycle.

Zeroing measures the offset at one pose; a real wrench's offset changes as the arm moves (README, *Bias
map*). At rest, with nothing touching the tool, the (sign-flipped) wrench at joint positions q with gravity
u = R_world_sensor^T g in the sensor frame reads, beyond the tool the settings already compensate,

    F = dm u + C_F p(q),        T = h x u + C_T p(q)

* the load part: a mass error dm [kg] and its first moment h = dm c [kg m] (a wrong payload set on a
  payload-compensating controller): it rotates with the tool;
* the residual: p(q) the monomials of the scaled joint positions up to `degree` (1: affine, 2: quadratic),
  one row of coefficients per wrench component: what friction and model errors leave, smooth in q.

Both are linear in the unknowns: one least-squares problem, with a small ridge on the residual's
non-constant terms so that an axis the sweep barely moves stays at zero. What the map leaves is measured on
poses it was not fitted on (`held_out_std`: five fits, each holding out a fifth of the poses), then the map
is fitted on all of them; the degree with the smaller held-out error is kept. A held-out pose's own reading
carries the sensor's noise, which the noise floor counts already: `error_std` takes it out (held-out
variance minus the noise variance the fitted poses show, unbiased for the terms fitted) and is what
contact_control adds to its floor. Outside the swept joint ranges q is clamped to them: the polynomial is not
extrapolated.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from itertools import combinations_with_replacement
from typing import Any

import numpy as np
import yaml
from compliant_common.errors import StackError
from compliant_common.typedefs import FloatArray

__all__ = ["BiasMap", "BiasMapError", "MapSample", "ResidualPredictor", "fit_bias_map", "load_bias_map"]

HOLD_OUT_EVERY = 5  # folds: each fit holds out every fifth pose, from another start
RIDGE = 1e-2  # on the residual's non-constant terms (scaled joint positions are of order 1)
MIN_SCALE = 0.05  # [rad] a joint that moves less in the sweep is scaled as if it moved this much
SAMPLES_PER_TERM = 1.5  # poses per residual term a degree needs to be tried


class BiasMapError(StackError):
    """Too few or unusable samples, or a map file that cannot be used (the message names the key)."""


@dataclass(frozen=True)
class MapSample:
    """One pose at rest: joint positions [rad] (in `BiasMap.joint_names` order), gravity in the sensor
    frame [m/s^2] and the mean sign-flipped wrench there, net of the configured tool [N, Nm]."""

    q: tuple[float, ...]
    gravity: tuple[float, float, float]
    wrench: tuple[float, ...]


def _terms(n: int, degree: int) -> list[tuple[int, ...]]:
    """The monomials' joint indices: () the constant, (i,) x_i, (i, j) x_i x_j."""
    out: list[tuple[int, ...]] = [()]
    for d in range(1, degree + 1):
        out.extend(combinations_with_replacement(range(n), d))
    return out


def _features(x: FloatArray, terms: Sequence[tuple[int, ...]]) -> FloatArray:
    """Monomials of scaled positions, one row per row of `x`."""
    x = np.atleast_2d(x)
    out = np.ones((x.shape[0], len(terms)))
    for k, term in enumerate(terms):
        for i in term:
            out[:, k] *= x[:, i]
    return out


def _skew(u: FloatArray) -> FloatArray:
    return np.array([[0.0, -u[2], u[1]], [u[2], 0.0, -u[0]], [-u[1], u[0], 0.0]])


@dataclass(frozen=True)
class BiasMap:
    """A fitted map; see the module docstring.

    Attributes:
        joint_names: The joints q is given for, in order.
        frame: The wrench's frame the map holds in (contact_control's ft_sensor_frame).
        mass: Load mass error dm [kg]; moment: its first moment h [kg m], sensor frame.
        degree: Of the residual polynomial (0: none).
        center, scale: q is used as (q - center) / scale [rad].
        lower, upper: The swept joint ranges [rad]; q is clamped into them.
        coefficients: 6 rows (fx..tz) of one coefficient per monomial.
        held_out_std: Per component, the std of what the map leaves on the held-out poses [N, Nm].
        fit_std: The same on the poses it was fitted on.
        error_std: `held_out_std` without the held-out readings' own noise: the map's error [N, Nm].
        samples: Poses fitted on; held_out: poses `held_out_std` was measured on.
        command: The command that reruns the calibration.
    """

    joint_names: tuple[str, ...]
    frame: str
    mass: float
    moment: tuple[float, float, float]
    degree: int
    center: tuple[float, ...]
    scale: tuple[float, ...]
    lower: tuple[float, ...]
    upper: tuple[float, ...]
    coefficients: tuple[tuple[float, ...], ...]
    held_out_std: tuple[float, ...]
    fit_std: tuple[float, ...]
    error_std: tuple[float, ...]
    samples: int
    held_out: int
    command: str = ""

    @property
    def residual_force(self) -> float:
        """The largest held-out force std [N]: what the map cannot explain."""
        return max(self.error_std[:3])

    @property
    def residual_torque(self) -> float:
        """The largest held-out torque std [Nm]."""
        return max(self.error_std[3:])

    def predict(self, q: Sequence[float], gravity: Sequence[float]) -> list[float]:
        """The offset at joint positions `q` with gravity `gravity` in the sensor frame [N, Nm]."""
        load = self.load_wrench(gravity)
        residual = self.predictor(self.joint_names)(q)
        return [a + b for a, b in zip(load, residual, strict=True)]

    def load_wrench(self, gravity: Sequence[float]) -> list[float]:
        """The load part alone: dm u and h x u."""
        ux, uy, uz = gravity
        hx, hy, hz = self.moment
        m = self.mass
        return [m * ux, m * uy, m * uz, hy * uz - hz * uy, hz * ux - hx * uz, hx * uy - hy * ux]

    def predictor(self, names: Sequence[str]) -> ResidualPredictor:
        """A predictor of the residual from joint states whose positions come in `names`' order.

        Raises:
            BiasMapError: A joint of the map is missing from `names`.
        """
        return ResidualPredictor(self, names)

    def describe(self) -> str:
        f = ", ".join(f"{v:.3f}" for v in self.held_out_std[:3])
        t = ", ".join(f"{v:.4f}" for v in self.held_out_std[3:])
        e = ", ".join(f"{v:.3f}" for v in self.error_std[:3])
        h = ", ".join(f"{v * 1e3:.2f}" for v in self.moment)
        return (f"bias map over {len(self.joint_names)} joints from {self.samples} poses: load error "
                f"{self.mass:+.4f} kg (moment {h} g m), residual of degree {self.degree}; left on the "
                f"{self.held_out} held-out poses: force std [{f}] N, torque std [{t}] Nm; without their "
                f"readings' noise the map's force error [{e}] N")

    # --- file ---
    def to_yaml(self) -> str:
        def nums(v: Sequence[float]) -> list[float]:
            return [float(f"{x:.6g}") for x in v]

        doc = {
            "frame": self.frame,
            "joint_names": list(self.joint_names),
            "load": {"mass": float(f"{self.mass:.6g}"), "moment": nums(self.moment)},
            "residual": {
                "degree": self.degree,
                "center": nums(self.center),
                "scale": nums(self.scale),
                "lower": nums(self.lower),
                "upper": nums(self.upper),
                "coefficients": [nums(row) for row in self.coefficients],
            },
            "held_out_std": nums(self.held_out_std),
            "fit_std": nums(self.fit_std),
            "error_std": nums(self.error_std),
            "samples": self.samples,
            "held_out": self.held_out,
            "command": self.command,
        }
        header = (f"# {self.describe()}\n# contact_control's bias_map (README, Bias map); rerun: "
                  f"{self.command or 'rosrun control_stack calibrate_bias'}\n")
        body: str = yaml.safe_dump(doc, sort_keys=False, width=120)
        return header + body


class ResidualPredictor:
    """The residual part of a map for joint states in a fixed name order: positions in, 6 floats out (it
    runs on every joint state: a few small numpy operations, ~9 us)."""

    def __init__(self, bias_map: BiasMap, names: Sequence[str]) -> None:
        missing = [n for n in bias_map.joint_names if n not in names]
        if missing:
            raise BiasMapError(f"bias_map: the joint state has no joint(s) {missing} the map was fitted for")
        self.names = tuple(names)
        self._index = np.array([list(names).index(n) for n in bias_map.joint_names], dtype=int)
        self._center = np.array(bias_map.center)
        self._scale = np.array(bias_map.scale)
        self._low = (np.array(bias_map.lower) - self._center) / self._scale
        self._high = (np.array(bias_map.upper) - self._center) / self._scale
        n = len(bias_map.joint_names)
        terms = _terms(n, bias_map.degree)
        # Each monomial as x_ext[first] * x_ext[second], x_ext = (x, 1): absent factors index the 1.
        self._first = np.array([t[0] if len(t) > 0 else n for t in terms], dtype=int)
        self._second = np.array([t[1] if len(t) > 1 else n for t in terms], dtype=int)
        self._coefficients = np.array(bias_map.coefficients, dtype=float)
        self._x = np.ones(n + 1)

    def __call__(self, positions: Sequence[float]) -> list[float]:
        """The residual [N, Nm] at a joint state's positions (in this predictor's name order)."""
        x = (np.asarray(positions, dtype=float)[self._index] - self._center) / self._scale
        np.clip(x, self._low, self._high, out=self._x[:-1])
        out: list[float] = (self._coefficients @ (self._x[self._first] * self._x[self._second])).tolist()
        return out


def fit_bias_map(
    joint_names: Sequence[str], samples: Sequence[MapSample], frame: str = "", command: str = "",
    degrees: Sequence[int] = (1, 2),
) -> BiasMap:
    """Fits a map; see the module docstring.

    Raises:
        BiasMapError: Too few poses, non-finite values, or orientations that cannot separate the load.
    """
    n = len(joint_names)
    rows = list(samples)
    if len(rows) < 2 * HOLD_OUT_EVERY:
        raise BiasMapError(f"need 10 or more poses at rest (a sweep of 30+ is better), got {len(rows)}")
    q = np.array([s.q for s in rows], dtype=float)
    u = np.array([s.gravity for s in rows], dtype=float)
    w = np.array([s.wrench for s in rows], dtype=float)
    if q.shape != (len(rows), n) or u.shape[1:] != (3,) or w.shape[1:] != (6,):
        raise BiasMapError(f"each pose needs {n} joint positions, a gravity 3-vector and a wrench 6-vector")
    if not (np.all(np.isfinite(q)) and np.all(np.isfinite(u)) and np.all(np.isfinite(w))):
        raise BiasMapError("a pose has NaN/inf values: sample it again")
    center = 0.5 * (q.min(axis=0) + q.max(axis=0))
    scale = np.maximum(q.std(axis=0), MIN_SCALE)
    fold = np.arange(len(rows)) % HOLD_OUT_EVERY
    training = len(rows) - int(np.sum(fold == 0))
    best: tuple[float, int, FloatArray, FloatArray] | None = None
    for degree in sorted(set(degrees)):
        terms = _terms(n, degree)
        if len(terms) * SAMPLES_PER_TERM > training and degree > min(degrees):
            continue  # too few poses for this many terms
        held_sq, noise = np.zeros(6), np.zeros(6)
        for k in range(HOLD_OUT_EVERY):
            held, fit = fold == k, fold != k
            x, fitted = _solve(q[fit], u[fit], w[fit], center, scale, terms)
            held_sq += np.sum(_residuals(x, q[held], u[held], w[held], center, scale, terms) ** 2, axis=0)
            dof = max(1, int(fit.sum()) - len(terms) - 1)  # per component: its terms and the load's share
            noise += np.sum(fitted**2, axis=0) / dof / HOLD_OUT_EVERY
        held_std = np.sqrt(held_sq / len(rows))
        map_error = np.sqrt(np.maximum(held_std**2 - noise, 0.0))
        score = float(np.sum(held_std[:3] ** 2) + np.sum((held_std[3:] * 10.0) ** 2))  # 10 Nm ~ 1 N at 0.1 m
        if best is None or score < best[0]:
            best = (score, degree, held_std, map_error)
    assert best is not None
    _, degree, held_std, map_error = best
    terms = _terms(n, degree)
    x, fit_error = _solve(q, u, w, center, scale, terms)
    coefficients = x[4:].reshape(6, len(terms))
    return BiasMap(
        joint_names=tuple(joint_names), frame=frame, mass=float(x[0]), moment=(x[1], x[2], x[3]),
        degree=degree, center=tuple(center.tolist()), scale=tuple(scale.tolist()),
        lower=tuple(q.min(axis=0).tolist()), upper=tuple(q.max(axis=0).tolist()),
        coefficients=tuple(tuple(r) for r in coefficients.tolist()),
        held_out_std=tuple(held_std.tolist()),
        fit_std=tuple(np.sqrt(np.mean(fit_error**2, axis=0)).tolist()),
        error_std=tuple(map_error.tolist()),
        samples=len(rows), held_out=len(rows), command=command,
    )


def _design(q: FloatArray, u: FloatArray, center: FloatArray, scale: FloatArray,
            terms: Sequence[tuple[int, ...]]) -> FloatArray:
    """Rows fx..tz per pose; columns dm, h (3), then 6 blocks of monomial coefficients."""
    p = _features((q - center) / scale, terms)
    k = len(terms)
    a = np.zeros((6 * len(q), 4 + 6 * k))
    for s in range(len(q)):
        r = 6 * s
        a[r:r + 3, 0] = u[s]
        a[r + 3:r + 6, 1:4] = -_skew(u[s])  # h x u = -u x h
        for c in range(6):
            a[r + c, 4 + c * k:4 + (c + 1) * k] = p[s]
    return a


def _solve(q: FloatArray, u: FloatArray, w: FloatArray, center: FloatArray, scale: FloatArray,
           terms: Sequence[tuple[int, ...]]) -> tuple[FloatArray, FloatArray]:
    """The least-squares unknowns and what they leave on these poses (a row per pose, fx..tz)."""
    a = _design(q, u, center, scale, terms)
    y = w.reshape(-1)
    k = len(terms)
    ridge = np.zeros(4 + 6 * k)
    for c in range(6):
        ridge[4 + c * k + 1:4 + (c + 1) * k] = math.sqrt(RIDGE * len(q))
    a_aug = np.vstack([a, np.diag(ridge)])
    y_aug = np.concatenate([y, np.zeros(len(ridge))])
    rank_check = np.linalg.svd(a[:, :4], compute_uv=False)
    if rank_check[-1] < 1e-3 * rank_check[0]:
        raise BiasMapError(
            "the poses' orientations are too alike to separate the load's mass and centre of mass: "
            "tilt the tool about two axes in the sweep")
    x = np.linalg.lstsq(a_aug, y_aug, rcond=None)[0]
    return x, (a @ x - y).reshape(-1, 6)


def _residuals(x: FloatArray, q: FloatArray, u: FloatArray, w: FloatArray, center: FloatArray,
               scale: FloatArray, terms: Sequence[tuple[int, ...]]) -> FloatArray:
    return (_design(q, u, center, scale, terms) @ x - w.reshape(-1)).reshape(-1, 6)


def load_bias_map(path: str) -> BiasMap:
    """A map file (`BiasMap.to_yaml`).

    Raises:
        BiasMapError: Unreadable, or a key missing or malformed (named).
    """
    try:
        with open(path) as handle:
            doc = yaml.safe_load(handle)
    except (OSError, yaml.YAMLError) as err:
        raise BiasMapError(f"bias_map {path}: {err}") from err
    if not isinstance(doc, dict):
        raise BiasMapError(f"bias_map {path}: not a mapping of keys")
    try:
        return _from_doc(doc)
    except (KeyError, TypeError, ValueError) as err:
        raise BiasMapError(f"bias_map {path}: {err}") from err


def _floats(value: Any, length: int, key: str) -> tuple[float, ...]:
    if not isinstance(value, list) or len(value) != length:
        raise ValueError(f"{key}: expected {length} numbers, got {value!r}")
    out = tuple(float(v) for v in value)
    if not all(math.isfinite(v) for v in out):
        raise ValueError(f"{key}: not finite: {value!r}")
    return out


def _from_doc(doc: dict[str, Any]) -> BiasMap:
    for key in ("joint_names", "load", "residual", "held_out_std"):
        if key not in doc:
            raise KeyError(f"no key {key!r}")
    names = doc["joint_names"]
    if not isinstance(names, list) or not names or not all(isinstance(n, str) for n in names):
        raise ValueError(f"joint_names: expected a list of joint names, got {names!r}")
    n = len(names)
    load, res = doc["load"], doc["residual"]
    degree = int(res["degree"])
    if degree not in (0, 1, 2):
        raise ValueError(f"residual.degree: 0, 1 or 2, got {degree}")
    k = len(_terms(n, degree))
    rows = res["coefficients"]
    if not isinstance(rows, list) or len(rows) != 6:
        raise ValueError("residual.coefficients: expected 6 rows (fx..tz)")
    scale = _floats(res["scale"], n, "residual.scale")
    if not all(s > 0.0 for s in scale):
        raise ValueError(f"residual.scale: must be > 0, got {scale}")
    return BiasMap(
        joint_names=tuple(names), frame=str(doc.get("frame", "")), mass=float(load["mass"]),
        moment=_floats(load["moment"], 3, "load.moment"),  # type: ignore[arg-type]
        degree=degree, center=_floats(res["center"], n, "residual.center"), scale=scale,
        lower=_floats(res["lower"], n, "residual.lower"), upper=_floats(res["upper"], n, "residual.upper"),
        coefficients=tuple(_floats(r, k, f"residual.coefficients[{i}]") for i, r in enumerate(rows)),
        held_out_std=_floats(doc["held_out_std"], 6, "held_out_std"),
        fit_std=_floats(doc.get("fit_std", [0.0] * 6), 6, "fit_std"),
        error_std=_floats(doc.get("error_std", doc["held_out_std"]), 6, "error_std"),
        samples=int(doc.get("samples", 0)), held_out=int(doc.get("held_out", 0)),
        command=str(doc.get("command", "")),
    )
