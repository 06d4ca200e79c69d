"""The curved demonstration's path checked before anything launches (robot_setup.path_reach): the lag
jog_arm's singularity slow-down leaves behind the path law's reference, and which committed arms can run
the path as planned."""

from __future__ import annotations

import pathlib

import numpy as np
import pytest
from contact_tasks.path_task import MAX_LAG, PATH_STIFFNESS
from robot_setup.check import check_package
from robot_setup.path_reach import predicted_lag

SRC = pathlib.Path(__file__).resolve().parents[2] / "src"
SPEED = 0.02  # [m/s] the curved demonstration's


def test_below_the_threshold_the_tool_keeps_up_and_arrives():
    lag, arrives = predicted_lag(np.linspace(3.0, 6.0, 61), 0.005, SPEED, 8.0, 12.0, 5.0)
    assert arrives and lag < 1e-3  # the reference's own step only


def test_a_slowed_stretch_leaves_the_lag_the_path_law_settles_at():
    # Scaled to s = 0.5 all along (condition 10 of 8..12, rising): the law's catch-up k e balances the
    # slow-down when s (v + k e) = v, so e = v (1 - s) / (s k) = 4 mm.
    lag, arrives = predicted_lag(np.linspace(10.0, 10.0 + 1e-6, 201), 0.005, SPEED, 8.0, 12.0, 5.0)
    assert arrives and lag == pytest.approx(SPEED * 0.5 / (0.5 * PATH_STIFFNESS), rel=0.05)


def test_the_hard_stop_holds_the_tool_until_the_path_law_ends_the_move():
    conditions = np.concatenate([np.linspace(4.0, 12.5, 30), np.full(31, 12.5) + np.linspace(0, 1e-6, 31)])
    lag, arrives = predicted_lag(conditions, 0.005, SPEED, 8.0, 12.0, 5.0)
    assert not arrives and lag > MAX_LAG


@pytest.mark.compute  # the checker builds each package's description and scene
@pytest.mark.parametrize("package, why", [
    ("ur5_custom", ""), ("panda_custom", ""),
    ("ur3_custom", "the move to the path's start: condition number"),
    ("tiago_custom", "the path, 0.105 m along it: condition number"),
    ("jaco2_custom", "the touch: j2s6s200_joint_2 reaches its limit"),
])
def test_the_checker_says_which_arms_cannot_run_the_curved_path_and_where(package, why):
    assert check_package(str(SRC / package)) == []  # not a problem of the package: make demo's [CANNOT]
    cannot = check_package.last_cannot
    if not why:
        assert cannot == {}
    else:
        assert cannot["curved_surface"].startswith(why), cannot
        assert "hard stop" in cannot["curved_surface"] or "limit" in cannot["curved_surface"]
