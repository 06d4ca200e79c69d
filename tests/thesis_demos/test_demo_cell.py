"""`make demo CELL=ur5_panda` as a user runs it (scripts/demo_cell): the UR5 and the Panda in one simulated
world, each arm's demonstrations at the same time, each arm's report apart, each arm's taught program in its
own folder (both teach one of the same name at once)."""

import pathlib
import subprocess

import pytest
from harness.launch import process_slot

ROOT = pathlib.Path(__file__).resolve().parents[2]

pytestmark = [pytest.mark.e2e, pytest.mark.cell]  # scripts/demo_cell runs the simulation


def test_both_arms_of_the_cell_pass_their_demonstrations_at_the_same_time(tmp_path):
    command = [str(ROOT / "scripts/with_env"), "python", str(ROOT / "scripts/demo_cell"), "--cell",
               "ur5_panda", "--only", "spring_x", "teach_and_replay", "--output", str(tmp_path)]
    with process_slot():
        run = subprocess.run(command, capture_output=True, text=True, timeout=600, check=False)
    assert run.returncode == 0, run.stdout[-4000:] + run.stderr[-3000:]
    assert "in one world" in run.stdout
    for arm in ("left", "right"):
        assert f"[{arm}] [PASS] spring_x" in run.stdout and f"[{arm}] [PASS] teach_and_replay" in run.stdout
        assert (tmp_path / arm / "report.md").exists() and (tmp_path / arm / "spring_x.png").exists()
        program = tmp_path / "ros_home" / "compliant_programs" / arm / "thesis_demos_teach_and_replay.yaml"
        assert program.exists()
    assert "all demonstrations passed on every arm" in run.stdout


def test_an_unknown_cell_is_refused_naming_the_file(tmp_path):
    command = [str(ROOT / "scripts/with_env"), "python", str(ROOT / "scripts/demo_cell"), "--cell", "no_such"]
    run = subprocess.run(command, capture_output=True, text=True, timeout=120, check=False)
    assert run.returncode == 2 and "no_such.yaml: cannot read" in run.stderr, run.stderr
