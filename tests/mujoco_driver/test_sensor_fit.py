"""mujoco_driver.sensor_fit and the fit_sensor command, on generated recordings only (seeded, no sleeps).

A recording: white noise + AR(1) drift (exact Ornstein-Uhlenbeck steps on the jittered sample times) at
known stds and tau on all six axes, a rest window, a gap, a press with a one-sample onset step, the rest
offset shifted by the press, and a second rest window. The fit must recover the stds (15 %), tau (30 %), the
rate, the gap, the jump and the offset shift; the command must read the same data from a UR-logger CSV (the
nanosecond field wrapping every second) and from a bag.
"""

from __future__ import annotations

import math
import os
import pathlib
import re
import subprocess
import sys
from dataclasses import dataclass

import numpy as np
import pytest
import yaml
from harness.bags import typestore, write_bag

from mujoco_driver import sensor_fit as sf

ROOT = pathlib.Path(__file__).resolve().parents[2]
SRC = ROOT / "src" / "mujoco_driver" / "src"
SCRIPT = ROOT / "src" / "mujoco_driver" / "scripts" / "fit_sensor"
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


def check_fit(result: sf.SensorFit, data: Synth, axis_tau_tol: float = 0.30) -> None:
    """stds within 15 %, the profile's tau (the median of the force axes') within 30 %, each axis's within
    ``axis_tau_tol``; rate, gap, jump, rest windows and the offset shift."""
    std_tol = 0.15
    assert result.rate == pytest.approx(data.rate, rel=2e-3)
    assert [(g.time, g.length) for g in result.gaps] == [(pytest.approx(data.gap_time, abs=1e-9),
                                                          pytest.approx(data.gap_length, abs=1e-9))]
    for axis, fit in enumerate(result.axes):
        assert fit.white == pytest.approx(WHITE[axis], rel=std_tol), fit
        assert fit.drift == pytest.approx(DRIFT[axis], rel=std_tol), fit
        assert fit.tau == pytest.approx(data.tau, rel=axis_tau_tol), fit
        assert fit.fitted_std == pytest.approx(fit.std, rel=0.1)
    assert result.common_tau == pytest.approx(data.tau, rel=0.30)
    for axis, (white, drift) in enumerate(result.common):
        assert white == pytest.approx(WHITE[axis], rel=std_tol)
        assert drift == pytest.approx(DRIFT[axis], rel=std_tol)
    fz = result.jumps[2]
    assert fz.value == pytest.approx(data.onset_step, abs=2.0)
    assert fz.time == pytest.approx(data.press[0], abs=1.5 / data.rate)
    # Rest windows: the gap splits the first rest; none inside the press; the fit takes the longest.
    windows = result.rest_windows
    assert len(windows) >= 2
    assert windows[0].t0 < 0.1 * data.rest[0][1] and windows[0].t1 <= data.gap_time + 1e-9
    assert windows[-1].t1 == pytest.approx(data.t[-1]) and windows[-1].t0 < data.rest[1][0] + 1.0
    assert all(w.t1 <= data.press[0] or w.t0 >= data.press[1] for w in windows)
    assert result.fit_window == windows[-1]
    shift = result.shift
    assert shift is not None and result.contact
    assert np.allclose(shift.change, SHIFT, atol=[0.1, 0.1, 0.1, 0.005, 0.005, 0.005])
    assert shift.peak == pytest.approx(data.peak, abs=2.0)
    assert data.press[0] < shift.peak_time < data.press[1]
    assert shift.fraction == pytest.approx(np.linalg.norm(SHIFT[:3]) / data.peak, rel=0.06)


@pytest.fixture(scope="module")
def fast() -> Synth:
    """500 Hz, tau 20 ms (10 samples), 30 s at rest on each side of a 2 s press."""
    return synthesize(500.0, 0.02, 30.0, seed=1)


@pytest.fixture(scope="module")
def slow() -> Synth:
    """30 Hz (franka_state_controller's default), tau 0.2 s (6 samples), 150 s at rest on each side."""
    return synthesize(30.0, 0.2, 150.0, seed=2, press_s=3.0, gap_s=0.3)


def test_fit_recovers_the_model_at_500_hz(fast):
    check_fit(sf.fit_recording(fast.t, fast.w, source="fast"), fast)


def test_fit_recovers_the_model_at_30_hz(slow):
    # 4500 samples, 750 tau: one axis's tau is good to ~17 % rms here, the median of three better.
    check_fit(sf.fit_recording(slow.t, slow.w, source="slow"), slow, axis_tau_tol=0.5)


def test_the_autocovariance_fit_agrees_on_a_long_window(fast):
    result = sf.fit_recording(fast.t, fast.w, method="acf")
    for axis, fit in enumerate(result.axes[:3]):
        assert fit.white == pytest.approx(WHITE[axis], rel=0.15)
        assert fit.drift == pytest.approx(DRIFT[axis], rel=0.15)
        assert fit.tau == pytest.approx(fast.tau, rel=0.4)


def test_given_windows_are_used_in_order(fast):
    result = sf.fit_recording(fast.t, fast.w, rest=[(1.0, 6.0), (-10.0, None)])
    assert result.fit_window.given and result.fit_window.t0 == pytest.approx(1.0, abs=0.01)
    assert result.fit_window.t1 == pytest.approx(6.0, abs=0.01)
    assert result.rest_windows[1].t0 == pytest.approx(fast.t[-1] - 10.0, abs=0.01)
    assert np.allclose(result.shift.change[:3], SHIFT[:3], atol=0.1)
    with pytest.raises(sf.SensorFitError, match="too few samples"):
        sf.fit_recording(fast.t, fast.w, rest=[(3.0, 3.01)])


def test_white_noise_has_no_drift_and_a_short_window_says_so():
    rng = np.random.default_rng(3)
    white = rng.normal(0.0, 0.5, 4000)
    fit = sf.fit_axis(white, 0.002)
    assert fit.tau is None and fit.drift == 0.0 and "no drift seen" in fit.note
    assert fit.white == pytest.approx(0.5, rel=0.05)
    # A drift with tau = 2 s seen through a 1 s window: tau undetermined, the window's share a lower bound.
    n, a = 500, math.exp(-0.002 / 2.0)
    drift = np.empty(n)
    drift[0] = 0.0
    for k in range(1, n):
        drift[k] = a * drift[k - 1] + 0.5 * math.sqrt(1 - a * a) * rng.standard_normal()
    fit = sf.fit_axis(drift + rng.normal(0.0, 0.1, n), 0.002)
    assert fit.tau is None and "window too short" in fit.note
    assert fit.white == pytest.approx(0.1, rel=0.3)
    t = np.arange(n) * 0.002
    result = sf.fit_recording(t, np.column_stack([drift + rng.normal(0.0, 0.1, n)] * 6), rest=[(None, None)])
    assert result.common_tau is None
    section = sf.profile_section(result)
    assert set(section) == {"noise_force", "noise_torque"}
    assert "undetermined" in sf.format_report(result)
    assert "No drift keys" in sf.yaml_text(result, "x.csv")


def test_profile_section_and_yaml(fast):
    result = sf.fit_recording(fast.t, fast.w, source="fast.csv")
    section = sf.profile_section(result)
    assert list(section) == ["noise_force", "noise_torque", "drift_force", "drift_torque",
                             "drift_time_constant", "contact_shift_fraction", "contact_shift_threshold"]
    assert np.allclose(section["noise_force"], WHITE[:3], rtol=0.15)
    assert np.allclose(section["drift_torque"], DRIFT[3:], rtol=0.15)
    assert section["contact_shift_threshold"] == pytest.approx(0.5 * fast.peak, abs=1.0)
    text = sf.yaml_text(result)
    assert yaml.safe_load(text) == {"wrench": section}
    lines = text.splitlines()
    for key in section:
        i = next(j for j, line in enumerate(lines) if line.startswith(f"  {key}:"))
        assert lines[i - 1].startswith("  # ") and "fast.csv" in lines[i - 1]


def test_csv_readers(tmp_path, fast):
    header = tmp_path / "header.csv"
    t_us = 1_708_857_503_929_545 + np.round(fast.t * 1e6).astype(np.int64)
    with open(header, "w") as f:
        f.write("t,fx,fy,fz,tx,ty,tz\n")
        for ti, row in zip(t_us[:2000], fast.w[:2000], strict=True):
            f.write(f"{ti}," + ",".join(repr(float(v)) for v in row) + "\n")
    notes: list[str] = []
    t, w = sf.load_csv(str(header), notes=notes)
    assert np.allclose(t, fast.t[:2000], atol=1e-6) and np.array_equal(w, fast.w[:2000])
    assert any("in us" in n for n in notes)
    named = tmp_path / "named.csv"
    with open(named, "w") as f:
        f.write("%time;field.wrench.force.x;field.wrench.force.y;field.wrench.force.z;field.wrench.torque.x;"
                "field.wrench.torque.y;field.wrench.torque.z;extra\n")
        for ti, row in zip(fast.t[:100], fast.w[:100], strict=True):
            f.write(f"{int(1.7e18 + ti * 1e9)};" + ";".join(repr(float(v)) for v in row) + ";0\n")
    t, w = sf.load_csv(str(named))
    assert np.allclose(t, fast.t[:100], atol=1e-6) and np.array_equal(w, fast.w[:100])
    headerless = tmp_path / "six.csv"
    np.savetxt(headerless, fast.w[:100], delimiter=" ")
    with pytest.raises(sf.SensorFitError, match="--rate"):
        sf.load_csv(str(headerless))
    t, _ = sf.load_csv(str(headerless), rate=100.0)
    assert t[-1] == pytest.approx(0.99)
    with pytest.raises(sf.SensorFitError, match="no column for tx"):
        sf.load_csv(str(headerless), columns=["fx", "fy", "fz", "-", "ty", "tz"], rate=100.0)


def write_ur_logger(path: pathlib.Path, data: Synth) -> None:
    """The UR logger's layout: sec written with 6 significant digits (useless), nsec wrapping each second."""
    start_ns = 1_648_540_000 * 10**9 + 860_297_000
    with open(path, "w") as f:
        for ti, row in zip(data.t, data.w, strict=True):
            ns = start_ns + round(ti * 1e9)
            f.write(f"{ns / 1e9:.6g},{ns % 10**9:.6g}," + ",".join(f"{v:.6g}" for v in row) + "\n")


def run_cli(*args: str) -> subprocess.CompletedProcess:
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(SRC), os.environ.get("PYTHONPATH", "")]))
    return subprocess.run([sys.executable, "-m", "mujoco_driver.sensor_fit", *args], capture_output=True,
                          text=True, timeout=120, check=False, env=env)


def test_ur_logger_csv_through_the_command(tmp_path, fast):
    csv_path = tmp_path / "wrench.csv"
    write_ur_logger(csv_path, fast)
    t, w = sf.load_csv(str(csv_path), layout="ur_logger")
    # %.6g of the nanoseconds keeps 6 digits: times good to 1 ms at worst, the unwrap exact over 42 s.
    assert len(t) == len(fast.t) and np.max(np.abs(t - fast.t)) < 1e-3
    assert np.allclose(w, fast.w, rtol=1e-5, atol=1e-5)
    default = run_cli(str(csv_path))
    assert default.returncode == 2 and "--csv-layout ur_logger" in default.stderr
    out = tmp_path / "fit.yaml"
    result = run_cli(str(csv_path), "--csv-layout", "ur_logger", "--write-yaml", str(out))
    assert result.returncode == 0, result.stderr
    report = result.stdout
    assert re.search(r"rate: 50\d\.\d Hz|rate: 49\d\.\d Hz", report)
    assert "gaps (> 3 median intervals): 1:" in report
    assert re.search(rf"\d+\.\d ms at {fast.gap_time:.3f} s", report)
    fz = next(line for line in report.splitlines() if line.startswith("fz "))
    assert re.search(rf"-(19|20|21)(\.\d)? N at {fast.press[0]:.3f} s", fz), fz
    assert "offset moved by" in report and "shift fraction" in report
    section = yaml.safe_load(out.read_text())["wrench"]
    assert np.allclose(section["noise_force"], WHITE[:3], rtol=0.15)
    assert np.allclose(section["drift_force"], DRIFT[:3], rtol=0.15)
    assert section["drift_time_constant"] == pytest.approx(fast.tau, rel=0.3)
    assert section["contact_shift_fraction"] == pytest.approx(np.linalg.norm(SHIFT[:3]) / fast.peak, rel=0.1)
    assert "# " in out.read_text() and "wrench.csv" in out.read_text()


def wrench_messages(topic: str, data: Synth, zero_stamps: bool = False) -> list:
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


def test_bag_through_the_command(tmp_path, slow):
    bag = tmp_path / "f_ext.bag"
    write_bag(bag, wrench_messages("/franka_state_controller/F_ext", slow))
    out = tmp_path / "fit.yaml"
    result = run_cli(str(bag), "--topic", "/franka_state_controller/F_ext", "--write-yaml", str(out))
    assert result.returncode == 0, result.stderr
    assert "rate: 30.0 Hz" in result.stdout
    assert re.search(rf"300\.0 ms at {slow.gap_time:.3f} s", result.stdout)
    section = yaml.safe_load(out.read_text())["wrench"]
    assert np.allclose(section["noise_force"], WHITE[:3], rtol=0.15)
    assert section["drift_time_constant"] == pytest.approx(slow.tau, rel=0.3)
    assert section["contact_shift_threshold"] == pytest.approx(0.5 * slow.peak, abs=1.0)
    missing = run_cli(str(bag), "--topic", "/wrench")
    assert missing.returncode == 2
    assert missing.stderr.count("\n") == 1
    assert "no topic '/wrench'" in missing.stderr
    assert "/franka_state_controller/F_ext (geometry_msgs/msg/WrenchStamped)" in missing.stderr


def test_bag_with_zero_stamps_uses_the_record_time(tmp_path, fast):
    short = Synth(fast.t[:200], fast.w[:200], fast.rate, fast.tau, 0, 0, (0, 0), ((0, 0), (0, 0)), 0, 0)
    bag = tmp_path / "zero.bag"
    write_bag(bag, wrench_messages("/wrench", short, zero_stamps=True))
    notes: list[str] = []
    t, w = sf.load_bag(str(bag), None, notes)
    assert np.allclose(t, short.t, atol=2e-9) and np.array_equal(w, short.w)
    assert "record times" in " ".join(notes)


def test_errors_are_one_line(tmp_path, fast):
    missing = run_cli(str(tmp_path / "nothing.csv"))
    assert missing.returncode == 2 and missing.stderr.strip().endswith("no such file")
    short = tmp_path / "short.csv"
    write_ur_logger(short, Synth(fast.t[:10], fast.w[:10], 500, 0, 0, 0, (0, 0), ((0, 0), (0, 0)), 0, 0))
    result = run_cli(str(short), "--csv-layout", "ur_logger")
    assert result.returncode == 2
    assert result.stderr.count("\n") == 1 and "too few samples (10 < 20)" in result.stderr
    # A recording that never rests: no window found, say how to give one.
    moving = tmp_path / "moving.csv"
    t = np.arange(2000) * 0.002
    ramp = np.column_stack([np.sin(2 * np.pi * 1.3 * t) * 20 * (1 + t)] * 6)
    np.savetxt(moving, np.column_stack([t, ramp]), delimiter=",", header="t,fx,fy,fz,tx,ty,tz", comments="")
    result = run_cli(str(moving), "--min-rest", "5")
    assert result.returncode == 2 and "--rest" in result.stderr


def test_the_script_runs_the_module(tmp_path, fast):
    assert os.access(SCRIPT, os.X_OK)
    assert SCRIPT.read_text().startswith("#!/usr/bin/env python3")
    result = subprocess.run([sys.executable, str(SCRIPT), "--help"], capture_output=True, text=True,
                            timeout=60, check=False)
    assert result.returncode == 0 and "--csv-layout" in result.stdout and "--write-yaml" in result.stdout
