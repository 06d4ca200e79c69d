"""Fixtures of the jog_arm tests: every behaviour test runs for a 6-joint and a 7-joint arm.

The helpers live in jog_arm_testing.py; pytest runs with --import-mode=importlib, which does not put
test directories on sys.path, so this file does.
"""

import pathlib
import sys

import pytest

_HERE = str(pathlib.Path(__file__).resolve().parent)
if _HERE not in sys.path:
    sys.path.insert(0, _HERE)

from jog_arm_testing import PANDA, UR5, Robot  # noqa: E402


@pytest.fixture(params=[UR5, PANDA], ids=lambda robot: robot.name)
def robot(request: pytest.FixtureRequest) -> Robot:
    """The UR5 (6 joints) and the Panda (7 joints, fingers locked)."""
    return request.param
