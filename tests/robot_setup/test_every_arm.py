"""Every serial manipulator of example-robot-data, found by reading the installed package (robot_setup.survey,
no list here): `make robot` with the flange found in its URDF, then `make check-robot`, as
`scripts/try_all_arms --no-demo` does. Each arm is generated and checked clean, or refused with one line that
says why; never a traceback. The table prints with -s; the demonstrations of every generated arm run by hand
with `scripts/try_all_arms` (robot_setup README)."""

from __future__ import annotations

import pathlib
import subprocess
import sys

import pytest
from robot_setup.survey import MIN_ARM_JOINTS, Arm, NotAnArm, arms, survey

ROOT = pathlib.Path(__file__).resolve().parents[2]


def test_the_survey_finds_the_arms_and_tells_why_the_rest_are_not_arms():
    everything = survey()
    found = {a.urdf: a for a in everything if isinstance(a, Arm)}
    assert found["ur_description/urdf/ur5_robot.urdf"].tip == "tool0"
    panda = found["panda_description/urdf/panda.urdf"]
    assert (panda.tip, panda.gripper) == ("panda_link8", ("panda_finger_joint1", "panda_finger_joint2"))
    assert found["z1_description/urdf/z1.urdf"].gripper == ("jointGripper",)
    assert len(found["so_arm_description/urdf/so100.urdf"].joints) == MIN_ARM_JOINTS  # its jaw is the gripper
    others = {a.urdf: a.reason for a in everything if isinstance(a, NotAnArm)}
    assert "solo_description/robots/solo12.urdf" in others  # a quadruped: its legs branch at the root
    assert "tiago_description/robots/tiago.urdf" in others  # an arm inside a robot: BASE= (tiago_custom)


# After the simulations, beside the other `compute` tests (make test): beside a simulation, even
# idle-scheduled, it slowed it.
@pytest.mark.compute
@pytest.mark.timeout(1800)  # its own: nine minutes of one core
def test_make_robot_and_make_check_robot_on_every_arm_of_the_library():
    """On two processes (both cores), under SCHED_IDLE (chrt --idle) should it run beside anything."""
    command = ["chrt", "--idle", "0", sys.executable, str(ROOT / "scripts" / "try_all_arms"), "--no-demo",
               "--jobs", "2"]
    run = subprocess.run(command, capture_output=True, text=True, timeout=1700, check=False)
    print(run.stdout[run.stdout.find("| URDF"):])
    assert run.returncode == 0 and "Traceback" not in run.stderr, run.stdout[-4000:] + run.stderr[-4000:]
    rows = [line for line in run.stdout.splitlines() if line.startswith("| ") and ".urdf | " in line]
    assert len(rows) == len(arms()), run.stdout
    for row in rows:
        made = row.split(" | ")[3]
        assert made.startswith(("generated, checked OK", "make robot: error: ")), row
    assert sum("checked OK" in row for row in rows) >= 10, rows  # UR3/5/10 variants, Jaco2, Panda, xArm7, Z1
