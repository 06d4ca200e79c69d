"""Fixtures of the sensor_fit tests: two generated recordings (500 Hz and 30 Hz).

The helpers live in sensor_fit_testing.py; pytest runs with --import-mode=importlib, which does not put
test directories on sys.path, so this file does.
"""

import pathlib
import sys

import pytest

_HERE = str(pathlib.Path(__file__).resolve().parent)
if _HERE not in sys.path:
    sys.path.insert(0, _HERE)

from sensor_fit_testing import Synth, synthesize  # noqa: E402


@pytest.fixture(scope="session")
def fast() -> Synth:
    """500 Hz, tau 20 ms (10 samples), 30 s at rest on each side of a 2 s press."""
    return synthesize(500.0, 0.02, 30.0, seed=1)


@pytest.fixture(scope="session")
def slow() -> Synth:
    """30 Hz (franka_state_controller's default), tau 0.2 s (6 samples), 150 s at rest on each side."""
    return synthesize(30.0, 0.2, 150.0, seed=2, press_s=3.0, gap_s=0.3)
