"""Generated recordings for the sensor_fit tests (seeded, no sleeps), and writers of the files they read.

A recording: white noise + AR(1) drift (exact Ornstein-Uhlenbeck steps on the jittered sample times) at
known stds and tau on all six axes, a rest window, a gap, a press with a one-sample onset step, the rest
offset shifted by the press, and a second rest window. Files: a UR-logger CSV (the nanosecond field wrapping
every second) and the messages of a bag.
"""

from __future__ import annotations

import math
import pathlib
from dataclasses import dataclass

import numpy as np
from harness.bags import typestore

__all__ = ["DRIFT", "OFFSET", "SHIFT", "WHITE", "Synth", "synthesize", "wrench_messages", "write_ur_logger"]

WHITE = np.array([0.30, 0.25, 0.40, 0.010, 0.012, 0.006])
DRIFT = np.array([0.20, 0.30, 0.25, 0.008, 0.010, 0.006])
OFFSET = np.array([3.0, -2.0, -18.0, 0.3, -0.1, 0.05])
SHIFT = np.array([1.5, -1.0, 2.5, 0.05, -0.04, 0.02])


@dataclass
class Synth:
    t: np.ndarray
    w: np.ndarray
    rate: float
    tau: float
    gap_time: float
    gap_length: float
    press: tuple[float, float]
    rest: tuple[tuple[float, float], tuple[float, float]]   # true rest spans (before, after the press)
    peak: float                                              # |press| at its peak [N]
    onset_step: float


def synthesize(rate: float, tau: float, rest_s: float, seed: int, press_s: float = 2.0, gap_s: float = 0.06,
               jitter: float = 0.02, onset_step: float = -20.0) -> Synth:
    """Rest (with a gap at 35 % of it), a press on -z (and +x) of ``press_s`` starting with a one-sample
    step, during which the offset moves by SHIFT, and rest again."""
    rng = np.random.default_rng(seed)
    dt = 1.0 / rate
    n = round((2 * rest_s + press_s) * rate)
    intervals = dt * (1.0 + jitter * np.clip(rng.standard_normal(n - 1), -3, 3))
    gap_time = 0.35 * rest_s
    k_gap = int(gap_time * rate)
    intervals[k_gap] = gap_s
    t = np.concatenate([[0.0], np.cumsum(intervals)])
    gap_time = float(t[k_gap])
    # AR(1) drift sampled exactly at the sample times: a_k = exp(-dt_k / tau).
    a = np.exp(-np.diff(t) / tau)
    e = rng.standard_normal((n, 6))
    drift = np.empty((n, 6))
    drift[0] = DRIFT * e[0]
    for k in range(1, n):
        drift[k] = a[k - 1] * drift[k - 1] + DRIFT * math.sqrt(1.0 - a[k - 1] ** 2) * e[k]
    w = OFFSET + WHITE * rng.standard_normal((n, 6)) + drift
    p0 = float(t[np.searchsorted(t, rest_s)])
    p1 = p0 + press_s
    s = np.clip((t - p0) / press_s, 0.0, 1.0)
    inside = (t >= p0) & (t < p1)
    press = np.where(inside, -onset_step * (1.0 - s) + 40.0 * np.sin(np.pi * s), 0.0)   # [N] magnitude
    w[:, 2] -= press
    w[:, 0] += 0.1 * press
    w += np.outer(s, SHIFT)                  # the offset moves during the press and stays
    peak = float(np.max(np.hypot(press, 0.1 * press)))
    return Synth(t, w, rate, tau, gap_time, gap_s, (p0, p1), ((0.0, rest_s), (p1, float(t[-1]))), peak,
                 onset_step)


def write_ur_logger(path: pathlib.Path, data: Synth) -> None:
    """The UR logger's layout: sec written with 6 significant digits (useless), nsec wrapping each second."""
    start_ns = 1_648_540_000 * 10**9 + 860_297_000
    with open(path, "w") as f:
        for ti, row in zip(data.t, data.w, strict=True):
            ns = start_ns + round(ti * 1e9)
            f.write(f"{ns / 1e9:.6g},{ns % 10**9:.6g}," + ",".join(f"{v:.6g}" for v in row) + "\n")


def wrench_messages(topic: str, data: Synth, zero_stamps: bool = False) -> list:
    """The recording as WrenchStamped messages for harness.bags.write_bag, recorded 0.15 ms after their
    stamps."""
    ts = typestore()
    wrench, header, body = (ts.types[n] for n in ("geometry_msgs/msg/WrenchStamped", "std_msgs/msg/Header",
                                                   "geometry_msgs/msg/Wrench"))
    vector, stamp = ts.types["geometry_msgs/msg/Vector3"], ts.types["builtin_interfaces/msg/Time"]
    start = 1_701_266_045 * 10**9
    messages = []
    for i, (ti, row) in enumerate(zip(data.t, data.w, strict=True)):
        ns = start + round(ti * 1e9)
        sec, nsec = (0, 0) if zero_stamps else divmod(ns, 10**9)
        msg = wrench(header=header(seq=i, stamp=stamp(sec=sec, nanosec=nsec), frame_id="panda_K"),
                     wrench=body(force=vector(x=row[0], y=row[1], z=row[2]),
                                 torque=vector(x=row[3], y=row[4], z=row[5])))
        messages.append((topic, "geometry_msgs/msg/WrenchStamped", ns + 150_000, msg))
    return messages
