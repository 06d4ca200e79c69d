"""scripts/speed_caps prints a robot package's collaborative speed caps: the hand's above the face's, each
the ISO/TS 15066 formula for the effective mass it prints."""

from __future__ import annotations

import pathlib
import re
import subprocess
import sys

import pytest
from jog_arm.body_regions import REGIONS, max_speed

pytestmark = pytest.mark.cobot_safety

SCRIPT = pathlib.Path(__file__).resolve().parents[1] / "scripts" / "speed_caps"


def test_the_ur5_caps_follow_from_its_effective_masses():
    run = subprocess.run([sys.executable, str(SCRIPT), "ur5_custom", "--regions", "hand,face"],
                         capture_output=True, text=True, timeout=120)
    assert run.returncode == 0, run.stderr
    lines = run.stdout.splitlines()
    masses = [float(m) for m in re.findall(r"[+-][xyz]\s+([0-9.]+)", lines[1])]
    hand = [float(v) for v in re.findall(r"[+-][xyz]\s+([0-9.]+)", lines[2])]
    face = [float(v) for v in re.findall(r"[+-][xyz]\s+([0-9.]+)", lines[3])]
    assert len(masses) == len(hand) == len(face) == 6
    for m, h, f in zip(masses, hand, face, strict=True):
        assert h == pytest.approx(max_speed(REGIONS["hand"], m), abs=0.001)
        assert f == pytest.approx(max_speed(REGIONS["face"], m), abs=0.001) and f < h
