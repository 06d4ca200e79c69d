"""`make demo ROBOT=ur5 DRIVER=ur_robot_driver BAG=1` as a user runs it (scripts/demo): the simulated UR5
speaking as ur_robot_driver (125 Hz), calibrated first (no bias map yet), ur5_custom's hardware.launch on top
with the map, the demonstrations read the driver's wrench; the run is recorded into demo.bag."""

import pathlib
import re
import subprocess

import numpy as np
import pytest
from harness.bags import read_bag
from harness.demo_lines import free_replays
from harness.launch import process_slot

ROOT = pathlib.Path(__file__).resolve().parents[2]


def _run(command: list[str], **kwargs) -> subprocess.CompletedProcess:
    """The demo command, holding the suite's process slot (harness.launch.process_slot) as a launch does."""
    with process_slot():
        return subprocess.run(command, **kwargs)


def _demo(*args: str) -> list[str]:
    """`make demo`'s command line with these arguments."""
    return [str(ROOT / "scripts/with_env"), "python", str(ROOT / "scripts/demo"), *args]


@pytest.mark.e2e  # scripts/demo runs the simulation
def test_surface_following_through_the_emulated_ur_robot_driver_is_recorded(tmp_path):
    """Surface following against the 125 Hz driver holds 10 +- 1.5 N over the slide (it failed at 5.9-12.3 N
    while the simulated tool hopped on the block), and the bag holds the driver's wrench at its rate."""
    bias_map = tmp_path / "bias_map.yaml"
    command = _demo("--robot", "ur5", "--driver", "ur_robot_driver", "--only", "surface_following", "--bag",
                    "--output", str(tmp_path), "--bias-map", str(bias_map), "--calibration-poses", "12")
    run = _run(command, capture_output=True, text=True, timeout=300, check=False)
    assert run.returncode == 0, run.stdout[-3000:] + run.stderr[-3000:]
    assert "[demo] running the demonstrations: surface_following\n" in run.stdout
    assert "[PASS] surface_following" in run.stdout
    assert f"no bias map for ur_robot_driver at {bias_map}: calibrating first" in run.stdout
    assert bias_map.exists() and "held-out" in bias_map.read_text()
    assert "switched controllers: started joint_group_vel_controller" in run.stdout
    assert (tmp_path / "surface_following.png").exists() and (tmp_path / "report.md").exists()
    wrenches = [m for _, _, m in read_bag(tmp_path / "demo.bag", topics=["/wrench"])]
    assert len(wrenches) > 125 * 10, "less than 10 s of the driver's wrench in the bag"
    assert {m.header.frame_id for m in wrenches} == {"tool0_controller"}
    stamps = np.array([m.header.stamp.sec + 1e-9 * m.header.stamp.nanosec for m in wrenches])
    assert abs(np.median(np.diff(stamps)) - 1.0 / 125.0) < 0.001  # CB3's 125 Hz


@pytest.mark.e2e  # scripts/demo runs the simulation, twice
def test_peg_in_hole_runs_in_its_own_scene_through_the_emulated_franka_ros_and_joins_the_report(tmp_path):
    """The seventh demonstration needs the hole fixture and the peg tool: make demo relaunches the emulated
    franka_ros with them after the others, and its section joins the same report."""
    command = _demo("--robot", "panda", "--driver", "franka_ros", "--only", "spring_x", "peg_in_hole",
                    "--bias-map", "none", "--output", str(tmp_path))
    run = _run(command, capture_output=True, text=True, timeout=400, check=False)
    assert run.returncode == 0, run.stdout[-3000:] + run.stderr[-3000:]
    assert "[demo] running the demonstrations: spring_x\n" in run.stdout
    assert "[demo] relaunching with fixture:=hole tool:=peg hole_seed:=1" in run.stdout
    said = (r"^\[PASS\] peg_in_hole: hole \+2\.7, -0\.9 mm and -1\.4 deg from nominal, not told to the "
            r"task; task succeeded: inserted 15 mm; (\d+\.\d) mm deep")
    verdict = re.search(said, run.stdout, re.M)
    assert verdict and float(verdict.group(1)) >= 15.0, run.stdout
    report = (tmp_path / "report.md").read_text()
    assert "2 of 2 passed" in report and "## Spring law on X" in report and "## Peg in hole" in report
    assert (tmp_path / "peg_in_hole.png").exists() and (tmp_path / "spring_x.png").exists()


def test_driver_options_without_a_driver_are_refused_before_anything_launches(tmp_path):
    command = _demo("--robot", "ur5", "--driver-options", "{series: e_series}", "--output", str(tmp_path))
    run = _run(command, capture_output=True, text=True, timeout=120, check=False)
    assert run.returncode == 2
    assert "--driver-options needs --driver" in run.stderr
    assert not (tmp_path / "launch.log").exists()


def test_a_curved_path_the_arm_cannot_run_is_named_and_nothing_launches(tmp_path):
    """On the UR3 the move to the curved path's start meets jog_arm's hard stop (a singularity): make demo
    says so before launching, and the exit status is [CANNOT]'s (nothing failed)."""
    command = _demo("--robot", "ur3", "--only", "curved_surface", "--output", str(tmp_path))
    run = _run(command, capture_output=True, text=True, timeout=120, check=False)
    assert run.returncode == 3, run.stdout + run.stderr
    assert re.search(r"^\[CANNOT\] curved_surface: this arm cannot do it as planned: the move to the path's "
                     r"start: condition number \d+\.\d, at or above jog_arm's hard stop 24", run.stdout, re.M)
    assert not (tmp_path / "launch.log").exists()


# Alone (after the parallel suite): beside another worker's simulations the UR3's pressed replay left
# 10 +- 1.5 N (50 ms means 8.15..11.78 N, docs/measurements.md); the timing cause is not found yet.
@pytest.mark.alone
def test_teach_and_replay_on_a_generated_arm(tmp_path):
    """The sixth demonstration as `make demo ROBOT=ur3` runs it: the L taught by the simulated hand is
    replayed in free space within 2 mm RMS / 5 mm max at 1 x and 2 x, and pressing on the block within
    10 +- 1.5 N; the program lands in the output folder's ros_home, not in the user's ~/.ros."""
    import os

    home = tmp_path / "home"
    command = _demo("--robot", "ur3", "--only", "teach_and_replay", "--output", str(tmp_path / "out"))
    run = _run(command, capture_output=True, text=True, timeout=300, check=False,
               env={**os.environ, "HOME": str(home)})
    assert run.returncode == 0, run.stdout[-3000:] + run.stderr[-3000:]
    assert "[PASS] teach_and_replay: taught -" in run.stdout
    for label in ("free space 1x", "free space 2x"):
        assert f"  {label}: program" in run.stdout
    # Pressing at the fraction of the taught speed that makes its top speed 1 cm/s (the hand's varies).
    pressed = r"^  pressing 10 N at 0\.\d+x: program .* force \d+\.\d\d N"
    assert re.search(pressed, run.stdout, re.M), run.stdout
    programs = tmp_path / "out" / "ros_home" / "compliant_programs"
    assert (programs / "thesis_demos_teach_and_replay.yaml").exists()
    assert not (home / ".ros" / "compliant_programs").exists()
    report = (tmp_path / "out" / "report.md").read_text()
    assert "teach_and_replay.png" in report and "free space 2x: path error max [mm]" in report


@pytest.mark.e2e  # scripts/demo runs the simulation
def test_free_replays_through_the_emulated_franka_ros_keep_the_taught_corner(tmp_path):
    """Through franka_ros (F_ext at 100 Hz, 20 ms trajectories: contact_control's command_latency 0.1 s),
    the taught L replays in free space within 5 mm of its path at 1 x and 2 x: the replay's fed-forward
    twist leads by that latency, so the tool turns the corner in time (with teach's 30 ms it cut it by
    6.2-7.2 mm at 2 x). The pressed replay's force is not judged here: it dips out of its band for under
    0.1 s in 2 of 5 runs where the tool sticks and slips (teach README, *Compliant replay*)."""
    command = _demo("--robot", "panda", "--driver", "franka_ros", "--only", "teach_and_replay",
                    "--bias-map", "none", "--output", str(tmp_path))
    run = _run(command, capture_output=True, text=True, timeout=300, check=False)
    free = free_replays(run.stdout)
    assert free, run.stdout[-3000:] + run.stderr[-3000:]
    rms_1x, max_1x, rms_2x, max_2x = free
    assert max(rms_1x, rms_2x) < 2.0 and max(max_1x, max_2x) < 5.0, free


@pytest.mark.e2e  # scripts/demo runs the simulation
def test_the_curved_surface_runs_in_its_own_scene_and_keeps_the_tool_normal(tmp_path):
    """The eighth demonstration: make demo relaunches the UR5 over the seeded cylinder with the ball-end tool;
    the 0.3 m path planned on the nominal cylinder is run at 10 N with the tool on the real normal."""
    command = _demo("--robot", "ur5", "--only", "curved_surface", "--output", str(tmp_path))
    run = _run(command, capture_output=True, text=True, timeout=300, check=False)
    assert run.returncode == 0, run.stdout[-3000:] + run.stderr[-3000:]
    line = next(x for x in run.stdout.splitlines() if x.startswith("[PASS] curved_surface"))
    assert line.startswith("[PASS] curved_surface: part -8.3, -5.3, +6.0 mm from nominal, not told to the "
                           "path; 0.300 m in "), line
    figures = {key: float(value) for key, value in re.findall(r"(force RMS error|max \|F\||true normal RMS) "
                                                               r"([0-9.]+)", line)}
    assert figures["force RMS error"] <= 1.5 and figures["max |F|"] <= 20.0
    assert figures["true normal RMS"] <= 3.0
    assert (tmp_path / "curved_surface.png").exists()


@pytest.mark.e2e  # scripts/demo runs the simulation
@pytest.mark.cell
def test_a_demonstration_runs_with_the_robot_in_a_namespace(tmp_path):
    """`--ns left`: the emulated UR driver, hardware.launch and the demonstrations all under /left (frames
    left/...); the controller switch and the wrench topic are found there."""
    command = _demo("--robot", "ur5", "--driver", "ur_robot_driver", "--ns", "left", "--only", "follower_z",
                    "--bias-map", "none", "--output", str(tmp_path))
    run = _run(command, capture_output=True, text=True, timeout=300, check=False)
    assert run.returncode == 0, run.stdout[-3000:] + run.stderr[-3000:]
    assert "[PASS] follower_z" in run.stdout
    log = (tmp_path / "launch.log").read_text()
    assert "/left/mujoco_driver/profile: ur_robot_driver" in log  # the driver's parameters
    assert "/left/contact_control_node/ft_in_topic: wrench" in log  # hardware.launch's
