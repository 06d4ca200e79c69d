"""Every robot package opens RViz with viewer:=rviz, in simulation and on hardware, on its own saved view
(fixed frame = its contact_control fixed_frame); without it, no RViz."""

from __future__ import annotations

import pathlib
import subprocess

import pytest
import yaml

SRC = pathlib.Path(__file__).resolve().parents[2] / "src"
PACKAGES = sorted(p.parents[1].name for p in SRC.glob("*/launch/hardware.launch"))


def _nodes(package: str, launch: str, *args: str) -> list[str]:
    run = subprocess.run(["roslaunch", "--nodes", package, launch, *args], capture_output=True, text=True,
                         timeout=60, check=False)
    assert run.returncode == 0, run.stderr
    return run.stdout.split()


def test_the_robot_packages_are_found():
    assert len(PACKAGES) >= 4, PACKAGES


@pytest.mark.parametrize("package", PACKAGES)
def test_viewer_rviz_starts_rviz_on_the_packages_view(package):
    view = yaml.safe_load((SRC / package / "config" / "view.rviz").read_text())
    cc = yaml.safe_load((SRC / package / "config" / "contact_control.yaml").read_text())
    assert view["Visualization Manager"]["Global Options"]["Fixed Frame"] == cc["fixed_frame"]
    for launch in ("sim.launch", "hardware.launch"):
        assert {"/rviz", "/stack_markers"} <= set(_nodes(package, launch, "viewer:=rviz")), launch
        assert "/rviz" not in _nodes(package, launch), launch
