"""Fit a force/torque sensor's noise model from a recording (pure: numpy and rosbags, no ROS).

Reads a wrench recording (a ROS 1 bag topic of geometry_msgs/WrenchStamped, or a CSV), finds the windows
where the sensor is at rest, and fits per axis: the offset (mean), white noise and a slow drift modelled as
an AR(1) process (stationary std and time constant). It also reports the sample rate and its jitter, gaps,
the largest one-sample jumps, and the offset change across a contact (first vs last rest window). The result
becomes a ``wrench:`` section for a driver profile (``config/profiles/*.yaml``): :func:`profile_section`,
:func:`yaml_text`. Command line: ``fit_sensor`` (or ``python -m mujoco_driver.sensor_fit``), see ``--help``.

Model of one axis at rest: ``x_k = offset + w_k + d_k`` with ``w`` white (std sigma_w) and
``d_k = a d_{k-1} + e_k``, ``a = exp(-dt/tau)`` (stationary std sigma_d). Its autocovariance is
``sigma_w^2 + sigma_d^2`` at lag 0 and ``sigma_d^2 a^k`` at lag k >= 1; its spectral density (the Fourier
transform of that) is ``sigma_w^2 + sigma_d^2 (1 - a^2) / (1 - 2 a cos(omega) + a^2)``. Two fits of it:

* ``whittle`` (default): the spectrum fitted to the rest window's periodogram by maximum likelihood
  (Whittle's approximation: minimise sum(log S + I / S) over the Fourier frequencies; for each tau of a
  log-spaced grid, refined around its best, sigma_w^2 and sigma_d^2 by scoring iterations). It leaves out
  frequency 0, so removing the window's mean does not bias it.
* ``acf``: the sample autocovariance (mean removed) at lags 1..K (K: twice the first lag where it falls
  below 2 var / sqrt(n)) fitted in least squares for each tau of the same grid, with lag 0 matched exactly
  (sigma_w^2 = var - sigma_d^2, clamped >= 0); the expected values include the bias of the mean's removal.
  On generated data (white 0.3 + drift 0.2, tau = 6 to 25 samples, windows of 200 to 1000 tau; 40 seeds
  each) its tau errors are heavier-tailed: rms 12-34 %, worst 2.2x, against Whittle's rms 8-19 %, worst
  43 %; its stds are also a little worse. Hence Whittle is the default.

tau is *undetermined* (None) when no positive lag-1 correlation is seen (lag-1 autocorrelation <=
3 / sqrt(n)) or, with Whittle, when white noise alone fits about as well (-log L within 3: a likelihood-ratio
test at 95 % for 2 parameters): then all the variance is white; when it comes out below half a sample
interval (drift indistinguishable from white); or when it comes out above a tenth of the window or, with
Whittle, some tau above a tenth of the window fits about as well (-log L within 2, 95 % for 1 parameter):
the window is too short to see the drift decorrelate, and the drift std printed is then the lag-1
autocovariance's square root, what the window shows, a lower bound. A window of T seconds gives a rough tau
unless T is some hundreds of tau: on generated data the rms error is 8 % at T = 1000 tau and 15-19 % at
200-400 tau; at T = 16 tau most fits say undetermined, and the few that do not underestimate tau by half.

Rest windows (when none are given), :data:`REST_RULE`: the centred moving standard deviation of each force
axis over ``max(0.2 s, 30 samples)``; the axis's reference is the 5th percentile of that moving std over
the whole recording (the noise of its quietest stretches); a sample is at rest when the moving std of every
force axis is at most 3 times its reference; rest windows are the runs of such samples at least
``min_rest`` (0.3 s) and 20 samples long, split at gaps. A quiet run between the first and the last whose
mean force is more than 10 references (the largest force axis's) away from both theirs is a steady hold
(a constant push), not rest, and is left out (listed in the report). This needs at least ~5 % of the
recording at rest, and it takes the first and the last quiet runs for rest: give the windows (``--rest``)
when the recording starts or ends in a hold.
"""

from __future__ import annotations

import argparse
import csv
import itertools
import math
import os
import re
import sys
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from compliant_common.errors import StackError

__all__ = [
    "AXES",
    "REST_RULE",
    "AxisFit",
    "ContactShift",
    "Gap",
    "Jump",
    "RestWindow",
    "SensorFit",
    "SensorFitError",
    "find_rest_windows",
    "fit_axis",
    "fit_recording",
    "format_report",
    "load_bag",
    "load_csv",
    "load_recording",
    "main",
    "profile_section",
    "yaml_text",
]

AXES = ("fx", "fy", "fz", "tx", "ty", "tz")
UNITS = ("N", "N", "N", "Nm", "Nm", "Nm")
CSV_LAYOUTS = ("auto", "ur_logger")
METHODS = ("whittle", "acf")
TIME_UNITS = {"s": 1.0, "ms": 1e-3, "us": 1e-6, "ns": 1e-9}
MIN_SAMPLES = 20            # in the recording and in a fit window
GAP_FACTOR = 3.0            # an interval longer than this many median intervals is a gap
REST_WINDOW_S = 0.2         # moving-std window of the rest detection [s] ...
REST_WINDOW_MIN = 30        # ... and at least this many samples
REST_PERCENTILE = 5.0       # the reference noise: this percentile of the moving std
REST_FACTOR = 3.0           # at rest: moving std <= this times the reference, on every force axis
TAU_MAX_FRACTION = 0.1      # tau is determined only up to this fraction of the fit window
HOLD_FACTOR = 10.0          # a quiet run this many reference stds from the first and last is a hold
LIKELIHOOD_WHITE = 3.0      # Whittle: the drift must lower -log L by this (chi2, 2 dof, 95 %: 6/2) ...
LIKELIHOOD_TAU = 2.0        # ... and every tau over a tenth of the window must fit worse by this (1 dof)
CONTACT_FACTOR = 10.0       # a press counts as a contact above this many times the largest force std
REST_RULE = (f"moving std over max({REST_WINDOW_S:g} s, {REST_WINDOW_MIN} samples) <= {REST_FACTOR:g} x its "
             f"{REST_PERCENTILE:g}th percentile over the recording, on every force axis; in between the "
             f"first and the last, mean force within {HOLD_FACTOR:g} x that percentile of either")


class SensorFitError(StackError):
    """The recording cannot be read or fitted; the message says why in one line."""


# ---------------------------------------------------------------------------------------------- loading

def _norm(name: str) -> str:
    return re.sub(r"[^a-z0-9]", "", name.strip().strip('"').lower())


def _axis_of(name: str) -> str | None:
    """fx..tz for a column name (``fx``, ``Fx``, ``force_x``, ``field.wrench.force.x``, ``mx``, ...)."""
    n = _norm(name)
    for i, c in enumerate("xyz"):
        if n in (f"f{c}",) or n.endswith(f"force{c}"):
            return AXES[i]
        if n in (f"t{c}", f"m{c}") or n.endswith(f"torque{c}"):
            return AXES[3 + i]
    return None


def _is_time(name: str) -> bool:
    n = _norm(name)
    return (n in ("t", "time", "stamp", "timestamp", "ts", "sec", "secs", "seconds")
            or n.startswith("time") or n.endswith("stamp") or re.fullmatch(r"t(s|ms|us|ns)", n) is not None)


def _time_unit(name: str, values: np.ndarray, unit: str | None) -> float:
    """Seconds per unit: ``unit`` if given, else a suffix of the column name (``t_us``, ``time_ms``), else
    the first value's magnitude (an epoch time: > 1e17 ns, > 1e14 us, > 1e11 ms), else seconds."""
    if unit is not None:
        if unit not in TIME_UNITS:
            raise SensorFitError(f"time unit {unit!r}: one of {sorted(TIME_UNITS)}")
        return TIME_UNITS[unit]
    m = re.search(r"(?:^|[^a-z])(s|ms|us|ns)$", name.strip().lower())
    if m:
        return TIME_UNITS[m.group(1)]
    first = abs(float(values[0])) if len(values) else 0.0
    for limit, scale in ((1e17, 1e-9), (1e14, 1e-6), (1e11, 1e-3)):
        if first > limit:
            return scale
    return 1.0


def _delimiter(line: str) -> str | None:
    for d in (",", ";", "\t"):
        if d in line:
            return d
    return None  # whitespace


def _read_rows(path: str) -> tuple[list[str] | None, np.ndarray]:
    """The header (None if the first row is all numbers) and the numeric rows of a delimited text file."""
    with open(path, newline="") as stream:
        lines = [ln for ln in stream.read().splitlines() if ln.strip() and not ln.lstrip().startswith("#")]
    if not lines:
        raise SensorFitError(f"{path}: empty file")
    delim = _delimiter(lines[0])
    rows = list(csv.reader(lines, delimiter=delim)) if delim else [ln.split() for ln in lines]
    header: list[str] | None = None
    try:
        [float(v) for v in rows[0]]
    except ValueError:
        header, rows = [v.strip() for v in rows[0]], rows[1:]
    width = len(header) if header is not None else len(rows[0]) if rows else 0
    data = np.full((len(rows), width), np.nan)
    for i, row in enumerate(rows):
        for j, v in enumerate(row[:width]):
            try:
                data[i, j] = float(v)
            except ValueError:
                pass  # a non-number cell: NaN (the row is dropped later if it is a wrench or time cell)
    return header, data


def _unwrap_nsec(nsec: np.ndarray) -> np.ndarray:
    """Seconds from 0 rebuilt from a nanosecond field alone (the UR logger's useless ``sec`` column):
    ``d = diff(nsec); d[d < 0] += 1e9; t = concat([0], cumsum(d)) * 1e-9`` (holes over 1 s are lost)."""
    d = np.diff(nsec)
    d[d < 0] += 1e9
    return np.concatenate([[0.0], np.cumsum(d)]) * 1e-9


def load_csv(path: str, columns: Sequence[str] | None = None, layout: str = "auto",
             time_column: str | int | None = None, time_unit: str | None = None,
             rate: float | None = None, notes: list[str] | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Read a wrench CSV.

    Args:
        path: The file: a header row with names (``fx..tz`` or ``force_x``, ``field.wrench.force.x``, ...;
            a ``t`` / ``time`` / ``stamp`` column) or headerless (6 columns: fx..tz, needs ``rate``;
            7: t, fx..tz; 8: sec, nsec, fx..tz). Comma, semicolon, tab or whitespace separated.
        columns: Names of the file's columns, in order (replace the header; ``-`` skips a column).
        layout: ``auto``, or ``ur_logger``: ``sec, nsec, fx, fy, fz, tx, ty, tz`` (no header) whose ``sec``
            column is useless: time is rebuilt from ``nsec`` alone by unwrapping its wraps.
        time_column: Name or 0-based index of the time column (else found by name).
        time_unit: ``s``, ``ms``, ``us`` or ``ns`` (else from the column name's suffix or the magnitude).
        rate: Sample rate [Hz] when the file has no time column.
        notes: Appended with what was assumed.

    Returns:
        Times [s] from 0 and an (N, 6) array fx fy fz tx ty tz; rows with a non-number are dropped.
    """
    if layout not in CSV_LAYOUTS:
        raise SensorFitError(f"CSV layout {layout!r}: one of {list(CSV_LAYOUTS)}")
    if not os.path.isfile(path):
        raise SensorFitError(f"{path}: no such file")
    notes = notes if notes is not None else []
    header, data = _read_rows(path)
    if layout == "ur_logger":
        if data.shape[1] < 8:
            raise SensorFitError(f"{path}: the ur_logger layout needs 8 columns (sec, nsec, fx..tz), "
                                 f"found {data.shape[1]}")
        data = data[np.all(np.isfinite(data[:, 1:8]), axis=1)]
        _check_count(path, len(data))
        notes.append("time rebuilt from the nsec column (ur_logger layout)")
        return _unwrap_nsec(data[:, 1]), data[:, 2:8]
    names = list(columns) if columns else header
    if names is None:
        defaults = {6: list(AXES), 7: ["t", *AXES], 8: ["sec", "nsec", *AXES]}
        if data.shape[1] not in defaults:
            raise SensorFitError(f"{path}: no header and {data.shape[1]} columns: name them with --columns "
                                 "(e.g. t,fx,fy,fz,tx,ty,tz)")
        names = defaults[data.shape[1]]
        notes.append(f"no header: columns taken as {','.join(names)}")
    if len(names) != data.shape[1]:
        raise SensorFitError(f"{path}: {len(names)} column names for {data.shape[1]} columns")
    index: dict[str, int] = {}
    for j, name in enumerate(names):
        axis = _axis_of(name)
        if axis and axis not in index:
            index[axis] = j
    missing = [a for a in AXES if a not in index]
    if missing:
        raise SensorFitError(f"{path}: no column for {', '.join(missing)} (columns: {', '.join(names)}; "
                             "name them with --columns)")
    cols = [index[a] for a in AXES]
    tcol: int | None
    if isinstance(time_column, int) or (isinstance(time_column, str) and time_column.isdigit()):
        tcol = int(time_column)
    elif isinstance(time_column, str):
        if time_column not in names:
            raise SensorFitError(f"{path}: no time column {time_column!r} (columns: {', '.join(names)})")
        tcol = names.index(time_column)
    else:
        times = [j for j, n in enumerate(names) if _is_time(n)]
        # rostopic echo -p: prefer the header stamp to %time (the record time)
        stamped = [j for j in times if _norm(names[j]).endswith("headerstamp")]
        tcol = (stamped or times)[0] if times else None
    nsec_col = next((j for j, n in enumerate(names) if _norm(n) in ("nsec", "nsecs", "nanosec", "nanosecs")),
                    None)
    keep = np.all(np.isfinite(data[:, cols]), axis=1)
    if tcol is not None:
        keep &= np.isfinite(data[:, tcol])
    dropped = int(len(data) - keep.sum())
    if dropped:
        notes.append(f"{dropped} rows with non-numbers dropped")
    data = data[keep]
    _check_count(path, len(data))
    wrench = data[:, cols]
    if tcol is None:
        if not rate:
            raise SensorFitError(f"{path}: no time column: give the sample rate (--rate HZ) or --time-column")
        notes.append(f"no time column: {rate:g} Hz assumed")
        return np.arange(len(wrench)) / rate, wrench
    raw = data[:, tcol]
    scale = _time_unit(names[tcol], raw, time_unit)
    t = (raw - raw[0]) * scale
    if nsec_col is not None and _norm(names[tcol]) in ("sec", "secs"):
        t = t + (data[:, nsec_col] - data[0, nsec_col]) * 1e-9
    if scale != 1.0 and time_unit is None:
        notes.append(f"time column {names[tcol]!r} read in {_unit_name(scale)}")
    _check_monotonic(path, t, "; a UR logger CSV needs --csv-layout ur_logger" if data.shape[1] == 8 else "")
    return t, wrench


def _unit_name(scale: float) -> str:
    return next(k for k, v in TIME_UNITS.items() if v == scale)


def _check_count(path: str, n: int) -> None:
    if n < MIN_SAMPLES:
        raise SensorFitError(f"{path}: too few samples ({n} < {MIN_SAMPLES})")


def _check_monotonic(path: str, t: np.ndarray, hint: str = "") -> None:
    back = np.flatnonzero(np.diff(t) < 0)
    if len(back):
        i = int(back[0])
        raise SensorFitError(f"{path}: time goes backwards at sample {i + 1} ({t[i]:.6g} -> {t[i + 1]:.6g} "
                             f"s, {len(back)} times){hint}")


def bag_topics(path: str) -> dict[str, str]:
    """Topic -> message type of a ROS 1 bag."""
    from rosbags.highlevel import AnyReader

    with AnyReader([Path(path)]) as reader:
        return {c.topic: c.msgtype for c in reader.connections}


def load_bag(path: str, topic: str | None = None,
             notes: list[str] | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Read a geometry_msgs/WrenchStamped topic of a ROS 1 bag (rosbags' AnyReader).

    Args:
        path: The bag.
        topic: The topic (None: the bag's only WrenchStamped topic).
        notes: Appended with what was assumed.

    Returns:
        Times [s] from 0 (the header stamps; the bag's record times if any stamp is zero) and an (N, 6)
        array fx fy fz tx ty tz.
    """
    from rosbags.highlevel import AnyReader

    if not os.path.isfile(path):
        raise SensorFitError(f"{path}: no such file")
    notes = notes if notes is not None else []
    try:
        reader = AnyReader([Path(path)])
        reader.open()
    except Exception as exc:
        raise SensorFitError(f"{path}: cannot read the bag: {exc}") from None
    try:
        topics = {c.topic: c.msgtype for c in reader.connections}
        listing = ", ".join(f"{k} ({v})" for k, v in sorted(topics.items())) or "none"
        if topic is None:
            wrenches = [k for k, v in topics.items() if v == "geometry_msgs/msg/WrenchStamped"]
            if len(wrenches) != 1:
                raise SensorFitError(f"{path}: give --topic (topics: {listing})")
            topic = wrenches[0]
            notes.append(f"topic {topic}")
        if topic not in topics:
            raise SensorFitError(f"{path}: no topic {topic!r} (topics: {listing})")
        if topics[topic] != "geometry_msgs/msg/WrenchStamped":
            raise SensorFitError(f"{path}: topic {topic} is {topics[topic]}, "
                                 "not geometry_msgs/msg/WrenchStamped")
        stamps, records, rows = [], [], []
        for conn, record_ns, raw in reader.messages(connections=[c for c in reader.connections
                                                                 if c.topic == topic]):
            msg: Any = reader.deserialize(raw, conn.msgtype)
            stamps.append(msg.header.stamp.sec * 1_000_000_000 + msg.header.stamp.nanosec)
            records.append(record_ns)
            f, m = msg.wrench.force, msg.wrench.torque
            rows.append((f.x, f.y, f.z, m.x, m.y, m.z))
    finally:
        reader.close()
    _check_count(f"{path} {topic}", len(rows))
    ns = np.asarray(stamps, dtype=np.int64)
    if np.any(ns == 0):
        notes.append("header stamps are zero: bag record times used")
        ns = np.asarray(records, dtype=np.int64)
    t = (ns - ns[0]).astype(float) * 1e-9
    _check_monotonic(f"{path} {topic}", t)
    return t, np.asarray(rows, dtype=float)


def _is_bag(path: str) -> bool:
    if path.endswith(".bag"):
        return True
    try:
        with open(path, "rb") as stream:
            return stream.read(13) == b"#ROSBAG V2.0\n"
    except OSError:
        return False


def load_recording(path: str, topic: str | None = None, notes: list[str] | None = None,
                   **csv_options) -> tuple[np.ndarray, np.ndarray]:
    """A bag (by its ``.bag`` suffix or its first line) or a CSV (``csv_options``: see :func:`load_csv`)."""
    if not os.path.isfile(path):
        raise SensorFitError(f"{path}: no such file")
    if _is_bag(path):
        return load_bag(path, topic, notes)
    return load_csv(path, notes=notes, **csv_options)


# ------------------------------------------------------------------------------------------------ results

@dataclass(frozen=True)
class RestWindow:
    """A stretch at rest: [t0, t1] [s], its sample count and per-axis mean (offset)."""

    t0: float
    t1: float
    n: int
    mean: tuple[float, ...]
    given: bool = False


@dataclass(frozen=True)
class AxisFit:
    """One axis fitted on the rest window.

    Attributes:
        axis, unit: ``fx`` .. ``tz``; N or Nm.
        offset: The window's mean.
        std: The window's sample standard deviation.
        white: White-noise std.
        drift: AR(1) drift's stationary std (a lower bound when tau is undetermined for a short window).
        tau: Drift time constant [s]; None when undetermined (``note`` says why).
        lag1: Lag-1 autocorrelation of the window.
        note: Why tau is undetermined ("" otherwise).
    """

    axis: str
    unit: str
    offset: float
    std: float
    white: float
    drift: float
    tau: float | None
    lag1: float
    note: str = ""

    @property
    def fitted_std(self) -> float:
        """The model's total std: sqrt(white^2 + drift^2)."""
        return math.hypot(self.white, self.drift)


@dataclass(frozen=True)
class Gap:
    """An interval over :data:`GAP_FACTOR` median intervals: starting at ``time`` [s], ``length`` [s]."""

    time: float
    length: float


@dataclass(frozen=True)
class Jump:
    """An axis's largest one-sample change over the recording: ``value`` at ``time`` (the later sample)."""

    axis: str
    unit: str
    value: float
    time: float
    after_gap: bool


@dataclass(frozen=True)
class ContactShift:
    """How the rest offset moved from the first to the last rest window, across the press in between.

    Attributes:
        first, last: The two rest windows.
        change: last.mean - first.mean, 6 axes.
        peak: Largest |F - first offset| between them [N] (the press a tared sensor would read).
        peak_force: That press's force vector (relative to the first offset) [N].
        peak_time: Its time [s].
    """

    first: RestWindow
    last: RestWindow
    change: tuple[float, ...]
    peak: float
    peak_force: tuple[float, float, float]
    peak_time: float

    @property
    def force_change(self) -> float:
        """|offset change| of the force [N]."""
        return float(np.linalg.norm(self.change[:3]))

    @property
    def fraction(self) -> float:
        """|force offset change| / peak press magnitude."""
        return self.force_change / self.peak if self.peak > 0 else 0.0


@dataclass
class SensorFit:
    """Everything :func:`fit_recording` found (see the module docstring for the methods)."""

    source: str
    n: int
    duration: float
    dt_median: float
    dt_std: float
    dt_min: float
    dt_max: float
    gaps: list[Gap]
    rest_windows: list[RestWindow]
    fit_window: RestWindow
    axes: list[AxisFit]
    jumps: list[Jump]
    shift: ContactShift | None
    contact: bool
    common_tau: float | None
    common: list[tuple[float, ...]]   # per axis (white, drift) refitted with common_tau
    min_rest: float = 0.3
    method: str = "whittle"
    notes: list[str] = field(default_factory=list)

    @property
    def rate(self) -> float:
        """Sample rate [Hz] from the median interval."""
        return 1.0 / self.dt_median


# --------------------------------------------------------------------------------------------------- fits

def _moving_std(x: np.ndarray, w: int) -> np.ndarray:
    """Centred moving std over w samples (edges: the nearest full window)."""
    n = len(x)
    if n <= w:
        return np.full(n, float(np.std(x)))
    y = x - np.median(x)
    c1 = np.concatenate([[0.0], np.cumsum(y)])
    c2 = np.concatenate([[0.0], np.cumsum(y * y)])
    s1 = c1[w:] - c1[:-w]
    s2 = c2[w:] - c2[:-w]
    std = np.sqrt(np.maximum(s2 / w - (s1 / w) ** 2, 0.0))   # len n - w + 1, window starting at i
    start = np.clip(np.arange(n) - w // 2, 0, n - w)
    return std[start]


def _runs(mask: np.ndarray) -> list[tuple[int, int]]:
    """[start, stop) index runs of True."""
    edges = np.diff(np.concatenate([[0], mask.astype(np.int8), [0]]))
    return list(zip(np.flatnonzero(edges == 1).tolist(), np.flatnonzero(edges == -1).tolist(), strict=True))


def _window(t: np.ndarray, w: np.ndarray, i0: int, i1: int, given: bool = False) -> RestWindow:
    return RestWindow(float(t[i0]), float(t[i1 - 1]), i1 - i0, tuple(float(v) for v in w[i0:i1].mean(axis=0)),
                      given)


def find_rest_windows(t: np.ndarray, w: np.ndarray, min_rest: float = 0.3,
                      holds: list[RestWindow] | None = None) -> list[RestWindow]:
    """Rest windows by :data:`REST_RULE` (module docstring), in time order; the quiet stretches left out as
    holds are appended to ``holds``."""
    dt = float(np.median(np.diff(t)))
    width = max(REST_WINDOW_MIN, round(REST_WINDOW_S / dt))
    s = np.column_stack([_moving_std(w[:, i], width) for i in range(3)])
    ref = np.percentile(s, REST_PERCENTILE, axis=0)
    ref = np.maximum(ref, 1e-9 * max(1.0, float(np.abs(w[:, :3]).max())))
    quiet = np.all(s <= REST_FACTOR * ref, axis=1)
    breaks = np.flatnonzero(np.diff(t) > GAP_FACTOR * dt) + 1   # a gap ends a window
    windows = []
    for start, stop in _runs(quiet):
        bounds = [start, *[int(b) for b in breaks if start < b < stop], stop]
        for i0, i1 in itertools.pairwise(bounds):
            if i1 - i0 >= MIN_SAMPLES and t[i1 - 1] - t[i0] >= min_rest:
                windows.append(_window(t, w, i0, i1))
    if len(windows) <= 2:
        return windows
    # A quiet stretch between them whose force is far from both the first and the last window's is a hold.
    tol = HOLD_FACTOR * float(ref.max())
    ends = [np.asarray(windows[0].mean[:3]), np.asarray(windows[-1].mean[:3])]
    kept = [windows[0]]
    for win in windows[1:-1]:
        if min(float(np.linalg.norm(np.asarray(win.mean[:3]) - e)) for e in ends) <= tol:
            kept.append(win)
        elif holds is not None:
            holds.append(win)
    return [*kept, windows[-1]]


def _autocov(x: np.ndarray, k_max: int) -> np.ndarray:
    """Sample autocovariance (mean removed, divisor n) at lags 0..k_max."""
    n = len(x)
    xc = x - x.mean()
    size = 1 << math.ceil(math.log2(2 * n))
    f = np.fft.rfft(xc, size)
    return np.fft.irfft(f * np.conj(f), size)[: k_max + 1] / n


def _white_expectation(n: int, k_max: int) -> np.ndarray:
    """E[sample autocovariance] of unit white noise, mean removed: (n-1)/n at 0, -(n-k)/n^2 after."""
    k = np.arange(k_max + 1)
    g = -(n - k) / n**2
    g[0] = (n - 1) / n
    return g


def _ar1_expectation(a: float, n: int, k_max: int) -> np.ndarray:
    """E[sample autocovariance] at lags 0..k_max of a unit-variance AR(1) (autocovariance a^k) with the
    sample mean removed (divisor n): ((n-k) a^k - sum_i (r_i + r_{i+k}) + (n-k) V) / n, with
    r_i = Cov(x_i, mean) and V = Var(mean)."""
    i = np.arange(n)
    r = ((1.0 - a ** (i + 1)) + (a - a ** (n - i))) / ((1.0 - a) * n)
    v = r.mean()
    p = np.concatenate([[0.0], np.cumsum(r)])
    k = np.arange(k_max + 1)
    s = p[n - k] + (p[n] - p[k])
    return ((n - k) * a**k - s + (n - k) * v) / n


def _acf_fixed(c: np.ndarray, n: int, a: float, k_max: int) -> tuple[float, float, float]:
    """Autocovariance fit for a given a: (sigma_w^2, sigma_d^2, residual), lags 1..k_max in least squares
    with lag 0 matched exactly (expected values with the window's mean removed)."""
    gw = _white_expectation(n, k_max)
    gd = _ar1_expectation(a, n, k_max)
    y = c[1 : k_max + 1] - c[0] * gw[1:] / gw[0]
    h = gd[1:] - gd[0] * gw[1:] / gw[0]
    hh = float(h @ h)
    s2d = float(y @ h) / hh if hh > 0 else 0.0
    s2d = min(max(s2d, 0.0), c[0] / gd[0])
    s2w = max((c[0] - s2d * gd[0]) / gw[0], 0.0)
    return s2w, s2d, float(np.sum((y - s2d * h) ** 2))


def _acf_lags(n: int, c: np.ndarray) -> int:
    """Lags used by the autocovariance fit: twice the first lag whose autocovariance falls below its noise
    (2 c0 / sqrt(n)), at least 10, at most n/4."""
    below = np.flatnonzero(c[1:] < 2.0 * c[0] / math.sqrt(n))
    first = int(below[0]) + 1 if len(below) else len(c) - 1
    return int(min(len(c) - 1, max(10, 2 * first)))


def _periodogram(x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Periodogram |DFT|^2 / n (mean removed) at the Fourier frequencies strictly between 0 and Nyquist,
    and cos(omega) there; its expectation is the spectral density S, whose mean over frequency is the
    variance."""
    n = len(x)
    m = (n - 1) // 2
    spec = np.abs(np.fft.rfft(x - x.mean())) ** 2 / n
    return spec[1 : m + 1], np.cos(2.0 * np.pi * np.arange(1, m + 1) / n)


def _ar1_spectrum(a: float, cosw: np.ndarray) -> np.ndarray:
    """Spectral density of a unit-variance AR(1): (1 - a^2) / (1 - 2 a cos(omega) + a^2)."""
    return (1.0 - a * a) / (1.0 - 2.0 * a * cosw + a * a)


def _whittle_fixed(spec: np.ndarray, g: np.ndarray) -> tuple[float, float, float]:
    """Whittle fit of S = sigma_w^2 + sigma_d^2 g for a given AR(1) shape g: (sigma_w^2, sigma_d^2, -log
    likelihood). With S = s h, h = q + (1 - q) g, the best scale s is mean(I / h) in closed form; q (the
    white share) is bracketed on a logistic grid, then found by safeguarded Newton steps on d(-log L)/dq, and
    compared with the boundaries (white only, drift only)."""
    m = len(spec)
    omg = 1.0 - g

    def nll(q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        h = q[:, None] + (1.0 - q[:, None]) * g[None, :]
        scale = np.mean(spec[None, :] / h, axis=1)
        return m * np.log(scale) + np.sum(np.log(h), axis=1) + m, scale

    def slope(q: float) -> tuple[float, float]:
        h = g + q * omg
        r = spec / h
        a = float(r.mean())
        b = float(np.mean(r * omg / h)) / a
        c = float(np.mean(r * (omg / h) ** 2)) / a
        k = omg / h
        return -m * b + float(k.sum()), m * (2.0 * c - b * b) - float(np.sum(k * k))

    u = np.linspace(-24.0, 24.0, 13)
    grid = 1.0 / (1.0 + np.exp(-u))
    values = np.concatenate([nll(grid[k : k + 4])[0] for k in range(0, len(grid), 4)])
    i = int(np.argmin(values))
    lo, hi = float(grid[max(i - 1, 0)]), float(grid[min(i + 1, len(grid) - 1)])
    q = float(grid[i])
    for _ in range(60):
        d1, d2 = slope(q)
        if d1 > 0.0:
            hi = q
        else:
            lo = q
        step = q - d1 / d2 if d2 > 0.0 else math.nan
        new = step if lo < step < hi else 0.5 * (lo + hi)
        if abs(new - q) <= 1e-14 + 1e-10 * q or hi - lo <= 1e-15:
            q = new
            break
        q = new
    value, scale = nll(np.array([q]))
    s_w = float(spec.mean())
    s_d = float(np.mean(spec / g))
    options = [(float(value[0]), float(scale[0]) * q, float(scale[0]) * (1.0 - q)),
               (m * math.log(s_w) + m, s_w, 0.0),
               (m * math.log(s_d) + float(np.sum(np.log(g))) + m, 0.0, s_d)]
    best, s2w, s2d = min(options)
    return s2w, s2d, best


def _search(cost, lo: float, hi: float) -> tuple[float, float]:
    """The tau in [lo, hi] with the smallest cost, and that cost: a log-spaced grid, then a finer one around
    its best."""
    grid = np.geomspace(lo, hi, 80)
    values = [cost(float(tau)) for tau in grid]
    i = int(np.argmin(values))
    fine = np.geomspace(grid[max(i - 1, 0)], grid[min(i + 1, len(grid) - 1)], 21)
    values_fine = [cost(float(tau)) for tau in fine]
    j = int(np.argmin(values_fine))
    return float(fine[j]), float(values_fine[j])


def _fit_fixed(x: np.ndarray, dt: float, tau: float, method: str) -> tuple[float, float]:
    """(sigma_w^2, sigma_d^2) of one axis with the drift's time constant fixed."""
    a = math.exp(-dt / tau)
    if method == "acf":
        n = len(x)
        c = _autocov(x, max(2, min(n // 4, 4000)))
        return _acf_fixed(c, n, a, _acf_lags(n, c))[:2]
    spec, cosw = _periodogram(x)
    return _whittle_fixed(spec, _ar1_spectrum(a, cosw))[:2]


def fit_axis(x: np.ndarray, dt: float, axis: str = "fx", unit: str = "N", method: str = "whittle") -> AxisFit:
    """White noise + AR(1) drift of one axis's rest samples ``x`` at interval ``dt`` (module docstring).

    Args:
        method: ``whittle`` (the model's spectrum fitted to the periodogram by maximum likelihood) or ``acf``
            (its autocovariance fitted to the sample autocovariance in least squares).
    """
    if method not in METHODS:
        raise SensorFitError(f"fit method {method!r}: one of {list(METHODS)}")
    x = np.asarray(x, dtype=float)
    n = len(x)
    if n < MIN_SAMPLES:
        raise SensorFitError(f"fit window: too few samples ({n} < {MIN_SAMPLES})")
    c = _autocov(x, max(2, min(n // 4, 4000)))
    std = float(np.sqrt(c[0] * n / (n - 1)))
    lag1 = float(c[1] / c[0]) if c[0] > 0 else 0.0
    span = n * dt
    common: dict[str, Any] = {"axis": axis, "unit": unit, "offset": float(x.mean()), "std": std, "lag1": lag1}
    if c[0] <= 0 or lag1 <= 3.0 / math.sqrt(n):
        return AxisFit(white=std, drift=0.0, tau=None, note=f"no drift seen (lag-1 correlation {lag1:.2f} "
                       f"<= 3/sqrt(n) = {3.0 / math.sqrt(n):.2f})", **common)
    if method == "acf":
        k_max = _acf_lags(n, c)

        def cost(tau: float) -> float:
            return _acf_fixed(c, n, math.exp(-dt / tau), k_max)[2]
    else:
        spec, cosw = _periodogram(x)

        def cost(tau: float) -> float:
            return _whittle_fixed(spec, _ar1_spectrum(math.exp(-dt / tau), cosw))[2]

    long_tau = TAU_MAX_FRACTION * span
    tau, best = _search(cost, 0.3 * dt, 0.5 * span)
    s2w, s2d = _fit_fixed(x, dt, tau, method)
    if method == "whittle" and s2d > 0.0:
        m = len(spec)
        gain = m * math.log(float(spec.mean())) + m - best        # -log L of white noise alone - the best
        if gain < LIKELIHOOD_WHITE:
            return AxisFit(white=std, drift=0.0, tau=None, note=f"no drift seen (the drift improves -log L "
                           f"by {gain:.2g} < {LIKELIHOOD_WHITE:g})", **common)
        if tau <= long_tau:
            margin = min(cost(float(v)) for v in np.geomspace(long_tau, 0.5 * span, 15)) - best
            if margin < LIKELIHOOD_TAU:
                tau = math.inf   # a tau beyond a tenth of the window fits about as well
    if s2d <= 0.0:
        return AxisFit(white=std, drift=0.0, tau=None, note="no drift fitted", **common)
    if tau < 0.5 * dt:
        return AxisFit(white=std, drift=0.0, tau=None,
                       note=f"drift faster than half a sample ({tau * 1e3:.2g} ms): counted as white",
                       **common)
    if tau > long_tau:
        s2d_seen = min(max(float(c[1]), 0.0), float(c[0]))
        return AxisFit(white=math.sqrt(c[0] - s2d_seen), drift=math.sqrt(s2d_seen), tau=None,
                       note=f"tau > {long_tau:.3g} s fits {'best' if tau < math.inf else 'about as well'}: "
                            "window too short to see the drift (drift std: the lag-1 autocovariance's root, "
                            "what the window shows: a lower bound)", **common)
    return AxisFit(white=math.sqrt(s2w), drift=math.sqrt(s2d), tau=tau, **common)


def _parse_window(t: np.ndarray, w: np.ndarray, t0: float | None, t1: float | None) -> RestWindow:
    end = float(t[-1])
    a = 0.0 if t0 is None else (end + t0 if t0 < 0 else t0)
    b = end if t1 is None else (end + t1 if t1 < 0 else t1)
    i0, i1 = int(np.searchsorted(t, a, "left")), int(np.searchsorted(t, b, "right"))
    if i1 - i0 < MIN_SAMPLES:
        raise SensorFitError(f"rest window {a:.3f}-{b:.3f} s: too few samples ({max(i1 - i0, 0)} < "
                             f"{MIN_SAMPLES}; the recording spans 0-{end:.3f} s)")
    return _window(t, w, i0, i1, given=True)


def fit_recording(t: np.ndarray, w: np.ndarray,
                  rest: Sequence[tuple[float | None, float | None]] | None = None, min_rest: float = 0.3,
                  source: str = "", notes: Sequence[str] = (), method: str = "whittle") -> SensorFit:
    """Fit the noise model of a wrench recording.

    Args:
        t: Times [s] (increasing).
        w: (N, 6) fx fy fz tx ty tz.
        rest: Rest windows (t0, t1) [s] (None: the recording's start / end; negative: from the end). The
            first is fitted; with two or more, the offset change is from the first to the last. Without
            them the windows are found by :func:`find_rest_windows` and the longest is fitted.
        min_rest: Shortest detected rest window [s].
        source: The recording's name (for the report).
        notes: Said in the report.
        method: ``whittle`` or ``acf`` (see :func:`fit_axis`).
    """
    t = np.asarray(t, dtype=float)
    w = np.asarray(w, dtype=float)
    if w.ndim != 2 or w.shape[1] != 6 or len(t) != len(w):
        raise SensorFitError(f"expected times (N,) and a wrench (N, 6), got {t.shape} and {w.shape}")
    if len(t) < MIN_SAMPLES:
        raise SensorFitError(f"{source or 'recording'}: too few samples ({len(t)} < {MIN_SAMPLES})")
    notes = list(notes)
    d = np.diff(t)
    dt = float(np.median(d))
    if dt <= 0:
        raise SensorFitError(f"{source or 'recording'}: the median sample interval is {dt} s")
    gaps = [Gap(float(t[i]), float(d[i])) for i in np.flatnonzero(d > GAP_FACTOR * dt)]
    if rest:
        windows = [_parse_window(t, w, a, b) for a, b in rest]
        fit_window = windows[0]
    else:
        holds: list[RestWindow] = []
        windows = find_rest_windows(t, w, min_rest, holds)
        for h in holds:
            notes.append(f"quiet {h.t0:.3f}-{h.t1:.3f} s left out: force away from the first and last rest "
                         f"offsets (a steady hold?), mean {' '.join(f'{v:.3g}' for v in h.mean[:3])} N")
        if not windows:
            raise SensorFitError(f"{source or 'recording'}: no rest window of {min_rest:g} s found "
                                 f"({REST_RULE}): give one with --rest T0:T1")
        fit_window = max(windows, key=lambda r: r.t1 - r.t0)
    i0 = int(np.searchsorted(t, fit_window.t0, "left"))
    i1 = i0 + fit_window.n
    inside = [g for g in gaps if fit_window.t0 <= g.time < fit_window.t1]
    if inside:
        notes.append(f"{len(inside)} gap(s) inside the fit window: lags counted in samples, not time")
    axes = [fit_axis(w[i0:i1, j], dt, AXES[j], UNITS[j], method) for j in range(6)]
    taus = [a.tau for a in axes[:3] if a.tau is not None]
    common_tau = float(np.median(taus)) if taus else None
    if common_tau is not None:
        tau = common_tau
        common = [tuple(math.sqrt(v) for v in _fit_fixed(w[i0:i1, j], dt, tau, method)) for j in range(6)]
    else:
        common = [(a.white, a.drift) for a in axes]
    jumps = []
    dw = np.diff(w, axis=0)
    for j in range(6):
        k = int(np.argmax(np.abs(dw[:, j])))
        jumps.append(Jump(AXES[j], UNITS[j], float(dw[k, j]), float(t[k + 1]), bool(d[k] > GAP_FACTOR * dt)))
    shift = None
    contact = False
    ordered = sorted(windows, key=lambda r: r.t0)
    if len(ordered) >= 2:
        first, last = ordered[0], ordered[-1]
        between = (t > first.t1) & (t < last.t0)
        if between.any():
            rel = w[between, :3] - np.asarray(first.mean[:3])
            mag = np.linalg.norm(rel, axis=1)
            k = int(np.argmax(mag))
            change = tuple(b - a for a, b in zip(first.mean, last.mean, strict=True))
            shift = ContactShift(first, last, change, float(mag[k]),
                                 (float(rel[k, 0]), float(rel[k, 1]), float(rel[k, 2])), float(t[between][k]))
            noise = max(a.std for a in axes[:3])
            contact = shift.peak > CONTACT_FACTOR * noise
    return SensorFit(source=source, n=len(t), duration=float(t[-1] - t[0]), dt_median=dt,
                     dt_std=float(d.std()), dt_min=float(d.min()), dt_max=float(d.max()), gaps=gaps,
                     rest_windows=windows, fit_window=fit_window, axes=axes, jumps=jumps, shift=shift,
                     contact=contact, common_tau=common_tau, common=common, min_rest=min_rest, method=method,
                     notes=notes)


# ----------------------------------------------------------------------------------------------- outputs

def _g(v: float, digits: int = 3) -> str:
    return f"{v:.{digits}g}"


def _tau_text(a: AxisFit) -> str:
    return f"{a.tau:.4g} s" if a.tau is not None else "undetermined"


def format_report(result: SensorFit) -> str:
    """A readable report: timing, rest windows, a table per axis, jumps and the offset change."""
    r = result
    lines = [f"recording: {r.source}" if r.source else "recording:"]
    lines += [f"  note: {n}" for n in r.notes]
    lines.append(f"samples: {r.n} over {r.duration:.3f} s")
    lines.append(f"rate: {r.rate:.1f} Hz (median interval {r.dt_median * 1e3:.3f} ms)")
    lines.append(f"jitter: interval std {r.dt_std * 1e3:.3f} ms, min {r.dt_min * 1e3:.3f} ms, "
                 f"max {r.dt_max * 1e3:.3f} ms")
    if r.gaps:
        shown = ", ".join(f"{g.length * 1e3:.1f} ms at {g.time:.3f} s" for g in r.gaps[:20])
        more = f" (+{len(r.gaps) - 20} more)" if len(r.gaps) > 20 else ""
        lines.append(f"gaps (> {GAP_FACTOR:g} median intervals): {len(r.gaps)}: {shown}{more}")
    else:
        lines.append(f"gaps (> {GAP_FACTOR:g} median intervals): none")
    how = "given" if r.fit_window.given else f"detected, >= {r.min_rest:g} s: {REST_RULE}"
    lines.append(f"rest windows ({how}):")
    for i, win in enumerate(r.rest_windows, 1):
        mark = "  <- fitted" if win == r.fit_window else ""
        mean = " ".join(f"{v:.3g}" for v in win.mean)
        lines.append(f"  #{i} {win.t0:.3f}-{win.t1:.3f} s ({win.n} samples), mean {mean}{mark}")
    span = r.fit_window.t1 - r.fit_window.t0
    lines.append(f"fit on {r.fit_window.t0:.3f}-{r.fit_window.t1:.3f} s ({r.fit_window.n} samples, "
                 f"{span:.3f} s): white noise + AR(1) drift per axis ({r.method} fit)")
    head = (f"{'axis':<5}{'unit':<5}{'offset':>10}{'std':>9}{'fit std':>9}{'white':>9}{'drift':>9}"
            f"{'tau':>13}{'lag1':>7}   largest jump")
    lines.append(head)
    for a, jump in zip(r.axes, r.jumps, strict=True):
        gap = ", after a gap" if jump.after_gap else ""
        lines.append(f"{a.axis:<5}{a.unit:<5}{a.offset:>10.4g}{a.std:>9.3g}{a.fitted_std:>9.3g}{a.white:>9.3g}"
                     f"{a.drift:>9.3g}{_tau_text(a):>13}{a.lag1:>7.2f}   "
                     f"{jump.value:+.3g} {jump.unit} at {jump.time:.3f} s{gap}")
    for a in r.axes:
        if a.note:
            lines.append(f"  {a.axis}: {a.note}")
    if r.common_tau is not None:
        lines.append(f"profile model (one tau = {r.common_tau:.4g} s, the median over the force axes): "
                     + ", ".join(f"{a}: white {_g(c[0])} drift {_g(c[1])}" for a, c in zip(AXES, r.common,
                                                                                            strict=True)))
    else:
        lines.append("profile model: tau undetermined on every force axis: no drift keys")
    s = r.shift
    if s is None:
        one = " (one found)" if len(r.rest_windows) == 1 else ""
        lines.append(f"offset change: needs two rest windows{one}")
    else:
        ch = " ".join(f"{a} {v:+.3g}" for a, v in zip(AXES, s.change, strict=True))
        i, j = r.rest_windows.index(s.first) + 1, r.rest_windows.index(s.last) + 1
        lines.append(f"offset change from rest #{i} ({s.first.t0:.2f}-{s.first.t1:.2f} s) to rest #{j} "
                     f"({s.last.t0:.2f}-{s.last.t1:.2f} s): {ch}")
        pf = ", ".join(f"{v:+.3g}" for v in s.peak_force)
        lines.append(f"  offset moved by {s.force_change:.3g} N after a {s.peak:.3g} N press (peak "
                     f"|F - offset #{i}| at {s.peak_time:.3f} s, F - offset = ({pf}) N): "
                     f"shift fraction {s.fraction:.3g}"
                     + ("" if r.contact else f" (peak < {CONTACT_FACTOR:g} x the force std: no contact, "
                                              "not used in the profile)"))
    return "\n".join(lines)


def _round(v: float, digits: int = 4) -> float:
    return float(f"{v:.{digits}g}")


def profile_section(result: SensorFit, digits: int = 4) -> dict:
    """The fitted keys of a driver profile's ``wrench`` section (WrenchSpec names).

    ``noise_force``/``noise_torque``: white std per axis [N, Nm]; ``drift_force``/``drift_torque``: AR(1)
    stationary std per axis and ``drift_time_constant`` [s]: one tau for all axes (the median of the force
    axes' determined taus; each axis's stds refitted with it), omitted when no force axis's tau is
    determined; ``contact_shift_fraction``: |force offset change| / peak press magnitude and
    ``contact_shift_threshold``: half the peak press magnitude [N] (a press of at least that size moves the
    offset), only when a contact was found between two rest windows.
    """
    r = result
    tau = r.common_tau
    source = r.common if tau is not None else [(a.white, 0.0) for a in r.axes]
    out: dict = {"noise_force": [_round(c[0], digits) for c in source[:3]],
                 "noise_torque": [_round(c[0], digits) for c in source[3:]]}
    if tau is not None:
        out["drift_force"] = [_round(c[1], digits) for c in source[:3]]
        out["drift_torque"] = [_round(c[1], digits) for c in source[3:]]
        out["drift_time_constant"] = _round(tau, digits)
    if r.shift is not None and r.contact:
        out["contact_shift_fraction"] = _round(r.shift.fraction, digits)
        out["contact_shift_threshold"] = _round(0.5 * r.shift.peak, digits)
    return out


def _yaml_value(v: object) -> str:
    if isinstance(v, list):
        return "[" + ", ".join(repr(float(x)) for x in v) + "]"
    return repr(float(v))  # type: ignore[arg-type]


def yaml_text(result: SensorFit, source: str | None = None, digits: int = 4) -> str:
    """:func:`profile_section` as YAML under ``wrench:``, each key with a comment saying where it comes
    from (merge the keys into a profile's wrench section; topic, frame and model are not fitted)."""
    r = result
    name = source if source is not None else r.source
    win = r.fit_window
    where = f"{name}, rest {win.t0:.3f}-{win.t1:.3f} s ({win.n} samples at {r.rate:.1f} Hz)"
    section = profile_section(r, digits)
    comments = {
        "noise_force": f"[N] white-noise std fx fy fz, fitted from {where}",
        "noise_torque": f"[Nm] white-noise std tx ty tz, fitted from {where}",
        "drift_force": f"[N] AR(1) drift stationary std fx fy fz (tau fixed below), fitted from {where}",
        "drift_torque": f"[Nm] AR(1) drift stationary std tx ty tz, fitted from {where}",
        "drift_time_constant": "[s] AR(1) drift time constant: median over the force axes "
                               f"({', '.join(a.axis for a in r.axes[:3] if a.tau is not None)}), "
                               f"fitted from {where}",
    }
    if r.shift is not None:
        s = r.shift
        across = (f"{name}, rest {s.first.t0:.2f}-{s.first.t1:.2f} s vs {s.last.t0:.2f}-{s.last.t1:.2f} s: "
                  f"offset moved {s.force_change:.3g} N after a {s.peak:.3g} N press at {s.peak_time:.2f} s")
        comments["contact_shift_fraction"] = f"|offset change| / peak press, from {across}"
        comments["contact_shift_threshold"] = f"[N] half the peak press, from {across}"
    undetermined = [a.axis for a in r.axes[:3] if a.tau is None]
    lines = [f"# Sensor model fitted by mujoco_driver's fit_sensor from {name}.",
             "# Merge these keys into a driver profile's wrench section (config/profiles/*.yaml)."]
    if "drift_time_constant" not in section:
        lines.append("# No drift keys: the drift's time constant is undetermined on every force axis "
                     "(see the report).")
        seen = [a.drift for a in r.axes]
        if any(v > 0.0 for v in seen):
            forces, torques = (", ".join(f"{v:.3g}" for v in part) for part in (seen[:3], seen[3:]))
            totals = ", ".join(f"{a.std:.3g}" for a in r.axes[:3])
            lines.append(f"# The window also shows a slow component (std at least {forces} N, {torques} Nm) "
                         f"left out: the emulated noise is quieter than the recording's ({totals} N in all).")
    elif undetermined:
        lines.append(f"# tau undetermined on {', '.join(undetermined)}: drift std refitted there with the "
                     "common tau (a slower component the window shows is not in it).")
    lines.append("wrench:")
    for key, value in section.items():
        lines.append(f"  # {comments[key]}")
        lines.append(f"  {key}: {_yaml_value(value)}")
    return "\n".join(lines) + "\n"


# ----------------------------------------------------------------------------------------------- command

def _window_arg(text: str) -> tuple[float | None, float | None]:
    try:
        a, b = text.split(":")
        return (float(a) if a.strip() else None, float(b) if b.strip() else None)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected T0:T1 in seconds (e.g. 0:0.8, -0.8: for the last 0.8 s), "
                                         f"got {text!r}") from None


def _parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(
        prog="fit_sensor",
        description="Fit a force/torque sensor's noise model (offset, white noise, AR(1) drift, rate, "
                    "jitter, jumps, offset shift after contact) from a recording, and write it as a driver "
                    "profile's wrench section.")
    p.add_argument("recording", help="a ROS 1 bag (geometry_msgs/WrenchStamped topic) or a CSV")
    p.add_argument("--topic", help="the bag's wrench topic (default: its only WrenchStamped topic)")
    p.add_argument("--rest", action="append", type=_window_arg, metavar="T0:T1",
                   help="a rest window [s] from the recording's start (negative: from its end; write "
                        "--rest=-0.8: for the last 0.8 s); repeat it: the first is fitted, the offset change "
                        "is from the first to the last in time. Default: found in the data")
    p.add_argument("--min-rest", type=float, default=0.3, help="shortest detected rest window [s] (0.3)")
    p.add_argument("--csv-layout", choices=CSV_LAYOUTS, default="auto",
                   help="ur_logger: sec,nsec,fx,fy,fz,tx,ty,tz without header, time rebuilt from nsec")
    p.add_argument("--columns", help="the CSV's column names, comma-separated (fx..tz, t; - to skip one)")
    p.add_argument("--time-column", help="the CSV's time column (name or 0-based index)")
    p.add_argument("--time-unit", choices=sorted(TIME_UNITS), help="unit of the CSV's time column")
    p.add_argument("--rate", type=float, help="sample rate [Hz] of a CSV without a time column")
    p.add_argument("--method", choices=METHODS, default="whittle",
                   help="whittle: spectrum fitted by maximum likelihood (default); "
                        "acf: autocovariance least squares")
    p.add_argument("--write-yaml", metavar="OUT.yaml", help="write the profile's wrench section there")
    return p


def main(argv: Sequence[str] | None = None) -> int:
    """Command-line entry point: prints the report; errors are one line on stderr, exit status 2."""
    args = _parser().parse_args(argv)
    notes: list[str] = []
    try:
        columns = args.columns.split(",") if args.columns else None
        t, w = load_recording(args.recording, topic=args.topic, notes=notes, columns=columns,
                              layout=args.csv_layout, time_column=args.time_column, time_unit=args.time_unit,
                              rate=args.rate)
        result = fit_recording(t, w, rest=args.rest, min_rest=args.min_rest,
                               source=os.path.basename(args.recording)
                               + (f" {args.topic}" if args.topic else ""), notes=notes, method=args.method)
        sys.stdout.write(format_report(result) + "\n")
        if args.write_yaml:
            try:
                with open(args.write_yaml, "w") as stream:
                    stream.write(yaml_text(result))
            except OSError as exc:
                raise SensorFitError(f"cannot write {args.write_yaml}: {exc.strerror}") from None
            sys.stdout.write(f"wrote {args.write_yaml}\n")
    except SensorFitError as exc:
        sys.stderr.write(f"fit_sensor: error: {exc}\n")
        return 2
    return 0


if __name__ == "__main__":
    sys.exit(main())
