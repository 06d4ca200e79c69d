"""The fit_sensor command (sensor_fit.cli; `python -m sensor_fit`, and the installed script) on generated
recordings: a UR-logger CSV and a bag through it, one-line errors."""

from __future__ import annotations

import os
import pathlib
import re
import subprocess
import sys

import numpy as np
import pytest
import yaml
from harness.bags import write_bag
from sensor_fit_testing import DRIFT, SHIFT, WHITE, Synth, wrench_messages, write_ur_logger

ROOT = pathlib.Path(__file__).resolve().parents[2]
SRC = ROOT / "src" / "sensor_fit" / "src"
SCRIPT = ROOT / "src" / "sensor_fit" / "scripts" / "fit_sensor"


def run_module(module: str, *args: str) -> subprocess.CompletedProcess:
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(SRC), os.environ.get("PYTHONPATH", "")]))
    return subprocess.run([sys.executable, "-m", module, *args], capture_output=True, text=True, timeout=120,
                          check=False, env=env)


def run_cli(*args: str) -> subprocess.CompletedProcess:
    return run_module("sensor_fit", *args)


def test_ur_logger_csv_through_the_command(tmp_path, fast):
    csv_path = tmp_path / "wrench.csv"
    write_ur_logger(csv_path, fast)
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


def test_the_package_and_its_cli_module_run_as_the_command():
    for module in ("sensor_fit", "sensor_fit.cli"):
        result = run_module(module, "--help")
        assert result.returncode == 0 and result.stderr == "", result.stderr
        assert result.stdout.startswith("usage: fit_sensor ") and "--write-yaml" in result.stdout
