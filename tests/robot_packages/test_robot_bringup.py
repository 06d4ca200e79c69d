"""A real robot's bring-up needs no simulator: every robot package's hardware.launch, and everything it
starts, depends on packages a robot install has, never on mujoco_driver (no ROS master; rospack and
roslaunch-deps read the workspace)."""

from __future__ import annotations

import pathlib
import subprocess

import pytest

SRC = pathlib.Path(__file__).resolve().parents[2] / "src"
HARDWARE = sorted(SRC.glob("*/launch/hardware.launch"))


def _words(*cmd: str) -> set[str]:
    out = subprocess.run(cmd, capture_output=True, text=True, timeout=60, check=True).stdout
    return set(out.split())


@pytest.mark.parametrize("launch", HARDWARE, ids=[p.parts[-3] for p in HARDWARE])
def test_hardware_launch_and_its_packages_do_not_depend_on_the_simulator(launch):
    package = launch.parts[-3]
    used = _words("roslaunch-deps", str(launch)) - {package}
    assert "control_stack" in used  # the stack's bring-up include and make_description
    needed = set(used)
    for dep in used:
        needed |= _words("rospack", "depends", dep)
    assert "mujoco_driver" not in needed, f"{package}/launch/hardware.launch needs mujoco_driver via {used}"


def test_there_are_hardware_launch_files_to_check():
    assert len(HARDWARE) >= 2
