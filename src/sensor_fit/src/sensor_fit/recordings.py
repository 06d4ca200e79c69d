"""Reading a wrench recording: a ROS 1 bag topic of geometry_msgs/WrenchStamped (rosbags) or a CSV, as
times [s] from 0 and an (N, 6) array fx fy fz tx ty tz (:data:`AXES`)."""

from __future__ import annotations

import csv
import os
import re
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from sensor_fit.errors import SensorFitError

__all__ = [
    "AXES",
    "CSV_LAYOUTS",
    "MIN_SAMPLES",
    "TIME_UNITS",
    "UNITS",
    "bag_topics",
    "load_bag",
    "load_csv",
    "load_recording",
]

AXES = ("fx", "fy", "fz", "tx", "ty", "tz")
UNITS = ("N", "N", "N", "Nm", "Nm", "Nm")
CSV_LAYOUTS = ("auto", "ur_logger")
TIME_UNITS = {"s": 1.0, "ms": 1e-3, "us": 1e-6, "ns": 1e-9}
MIN_SAMPLES = 20            # in the recording and in a fit window


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
