"""`make demo CELL=ur5_panda` as a user runs it (scripts/demo_cell): the UR5 and the Panda in one simulated
world, each arm's demonstrations at the same time, each arm's report apart, each arm's taught program in its
own folder (both teach one of the same name at once)."""

import pathlib
import subprocess

import pytest
from harness.launch import process_slot

ROOT = pathlib.Path(__file__).resolve().parents[2]

pytestmark = [pytest.mark.e2e, pytest.mark.cell]  # scripts/demo_cell runs the simulation


# Alone (after the parallel suite): two arms in one world is the suite's heaviest simulation (real-time
# factor 0.88 with nothing beside it, docs/measurements.md), and beside another worker the UR5's 2 x replay
# once ended 5.57 mm off its path (cause not found; the failed arm's details now print).
@pytest.mark.alone
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
        assert "[PASS] teach_and_replay" in (tmp_path / arm / "demos.log").read_text()
        program = tmp_path / "ros_home" / "compliant_programs" / arm / "thesis_demos_teach_and_replay.yaml"
        assert program.exists()
    assert "all demonstrations passed on every arm" in run.stdout


def test_an_unknown_cell_is_refused_naming_the_file(tmp_path):
    command = [str(ROOT / "scripts/with_env"), "python", str(ROOT / "scripts/demo_cell"), "--cell", "no_such"]
    run = subprocess.run(command, capture_output=True, text=True, timeout=120, check=False)
    assert run.returncode == 2 and "no_such.yaml: cannot read" in run.stderr, run.stderr


def test_the_cells_bimanual_demonstration_passes_in_its_own_scene(tmp_path):
    """The ninth demonstration: the UR5 holds the plate on a spring, the Panda presses 10 N on it and slides
    40 mm; both arms through their own namespaces, one placed in the other's frame through the cell's tf."""
    command = [str(ROOT / "scripts/with_env"), "python", str(ROOT / "scripts/demo_cell"), "--cell",
               "ur5_panda", "--only", "bimanual", "--output", str(tmp_path)]
    with process_slot():
        run = subprocess.run(command, capture_output=True, text=True, timeout=600, check=False)
    assert run.returncode == 0, run.stdout[-4000:] + run.stderr[-3000:]
    assert "left.tool:=plate" in run.stdout and "[PASS] bimanual" in run.stdout
    for words in ("force while sliding", "plate gave way", "holder back within"):
        assert any(words in line and line.endswith(" ok") for line in run.stdout.splitlines()), run.stdout
    folder = tmp_path / "bimanual"
    assert (folder / "report.md").exists() and (folder / "bimanual.png").exists()
    assert not (tmp_path / "left").exists()  # no other demonstration ran
