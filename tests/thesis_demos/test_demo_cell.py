"""`make demo CELL=ur5_panda` as a user runs it (scripts/demo_cell): the UR5 and the Panda in one simulated
world, each arm's demonstrations at the same time, each arm's report apart."""

import pathlib
import subprocess

import pytest
from harness.launch import process_slot

ROOT = pathlib.Path(__file__).resolve().parents[2]

pytestmark = [pytest.mark.e2e, pytest.mark.cell]  # scripts/demo_cell runs the simulation


def test_both_arms_of_the_cell_pass_their_demonstrations_at_the_same_time(tmp_path):
    command = [str(ROOT / "scripts/with_env"), "python", str(ROOT / "scripts/demo_cell"), "--cell",
               "ur5_panda", "--only", "follower_z", "spring_x", "--output", str(tmp_path)]
    with process_slot():
        run = subprocess.run(command, capture_output=True, text=True, timeout=600, check=False)
    assert run.returncode == 0, run.stdout[-4000:] + run.stderr[-3000:]
    assert "in one world" in run.stdout
    for arm in ("left", "right"):
        assert f"[{arm}] [PASS] follower_z" in run.stdout and f"[{arm}] [PASS] spring_x" in run.stdout
        assert (tmp_path / arm / "report.md").exists() and (tmp_path / arm / "follower_z.png").exists()
    assert "all demonstrations passed on every arm" in run.stdout


def test_an_unknown_cell_is_refused_naming_the_file(tmp_path):
    command = [str(ROOT / "scripts/with_env"), "python", str(ROOT / "scripts/demo_cell"), "--cell", "no_such"]
    run = subprocess.run(command, capture_output=True, text=True, timeout=120, check=False)
    assert run.returncode == 2 and "no_such.yaml: cannot read" in run.stderr, run.stderr
