"""`make demo CELL=ur5_panda` as a user runs it (scripts/demo_cell): the UR5 and the Panda in one simulated
world, each arm's demonstrations at the same time, each arm's report apart, each arm's taught program in its
own folder (both teach one of the same name at once)."""

import pathlib
import re
import subprocess

import pytest
from harness.demo_lines import free_replays, pressed_mean
from harness.launch import process_slot

ROOT = pathlib.Path(__file__).resolve().parents[2]

pytestmark = [pytest.mark.e2e, pytest.mark.cell]  # scripts/demo_cell runs the simulation


# Alone (after the parallel suite): two arms in one world is the suite's heaviest simulation (real-time
# factor 0.88 with nothing beside it, docs/measurements.md). Even alone, the Panda's pressed replay once left
# its 10 +- 1.5 N band (50 ms means down to 8.24 N) while teach's loop ran 0.11 s late and the tool's pose on
# tf was 0.13 s old: the band is judged where one arm runs (tests/teach, the demo command's tests); here the
# press must hold 10 N on average, and the free replays stay on their path.
_BAND_ONLY = re.compile(r" -- pressing 10 N at \S+: the force left 10 \+- 1\.5 N$")


@pytest.mark.alone
def test_both_arms_of_the_cell_pass_their_demonstrations_at_the_same_time(tmp_path):
    command = [str(ROOT / "scripts/with_env"), "python", str(ROOT / "scripts/demo_cell"), "--cell",
               "ur5_panda", "--only", "spring_x", "teach_and_replay", "--output", str(tmp_path)]
    with process_slot():
        run = subprocess.run(command, capture_output=True, text=True, timeout=600, check=False)
    said = run.stdout[-4000:] + run.stderr[-3000:]
    assert run.returncode in (0, 1) and "in one world" in run.stdout, said
    for arm in ("left", "right"):
        assert f"[{arm}] [PASS] spring_x" in run.stdout, said
        verdicts = [x for x in run.stdout.splitlines() if x.startswith(f"[{arm}] [")]
        line = next((x for x in verdicts if "teach_and_replay" in x), "")
        assert f"[{arm}] [PASS] teach_and_replay" in line or _BAND_ONLY.search(line), said
        free, held = free_replays(line), pressed_mean(line)
        assert free and held, said
        rms_1x, max_1x, rms_2x, max_2x = free
        assert max(rms_1x, rms_2x) < 2.0 and max(max_1x, max_2x) < 5.0 and abs(held - 10.0) < 0.5, line
        assert (tmp_path / arm / "report.md").exists() and (tmp_path / arm / "spring_x.png").exists()
        assert "teach_and_replay: taught" in (tmp_path / arm / "demos.log").read_text()
        program = tmp_path / "ros_home" / "compliant_programs" / arm / "thesis_demos_teach_and_replay.yaml"
        assert program.exists()
    assert run.returncode == 1 or "all demonstrations passed on every arm" in run.stdout, said


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
