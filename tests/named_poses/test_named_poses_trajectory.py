"""A planned joint trajectory (named_poses.trajectory): goals checked with control_msgs' codes, the desired
position sampled between points, the path and goal tolerances."""

from __future__ import annotations

import math

import numpy as np
import pytest
from named_poses.poses import UrdfJoint
from named_poses.trajectory import INVALID_GOAL, INVALID_JOINTS, Planned, Tolerance, TrajectoryError

JOINTS = ["a", "b"]
LIMITS = {"a": UrdfJoint("a", False, -1.0, 1.0, 1.0), "b": UrdfJoint("b", True, -math.inf, math.inf, 1.0)}


def plan(names=("b", "a"), points=((1.0, [0.2, 0.1], []), (2.0, [0.4, 0.3], [])), path=(), goal=(),
         goal_time=0.0) -> Planned:
    return Planned.check(JOINTS, LIMITS, list(names), list(points), list(path), list(goal), goal_time,
                         default_path=math.inf, default_goal=0.01, default_goal_time=1.0)


def test_a_goal_in_any_joint_order_comes_out_in_the_arms():
    p = plan()
    assert p.positions.tolist() == [[0.1, 0.2], [0.3, 0.4]] and p.duration == 2.0 and p.velocities is None
    assert p.goal_time == 1.0 and p.goal_tolerance.tolist() == [0.01, 0.01]
    assert np.isinf(p.path_tolerance).all()


@pytest.mark.parametrize(("kwargs", "code", "words"), [
    ({"names": ("a", "c")}, INVALID_JOINTS, "unknown: ['c']; missing: ['b']"),
    ({"names": ("a", "a")}, INVALID_JOINTS, "repeat"),
    ({"points": ()}, INVALID_GOAL, "no points"),
    ({"points": ((1.0, [0.0], []),)}, INVALID_GOAL, "1 positions, 0 velocities for 2 joints"),
    ({"points": ((1.0, [0.0, 0.0], []), (1.0, [0.0, 0.0], []))}, INVALID_GOAL, "must increase"),
    ({"points": ((1.0, [0.0, math.nan], []),)}, INVALID_GOAL, "not a finite number"),
    ({"points": ((1.0, [0.0, 1.5], []),)}, INVALID_GOAL, "a at 1.5000 is outside its URDF limits"),
    ({"goal": (Tolerance("z", 0.1),)}, INVALID_JOINTS, "goal_tolerance names 'z'"),
])
def test_a_bad_goal_is_refused_with_its_code_and_reason(kwargs, code, words):
    with pytest.raises(TrajectoryError) as err:
        plan(**kwargs)
    assert err.value.code == code and words in str(err.value)


def test_the_desired_position_is_linear_without_velocities_and_hermite_with_them():
    start = np.array([0.0, 0.0])
    p = plan()
    assert p.desired(0.5, start) == pytest.approx([0.05, 0.1])  # from where the arm was to the first point
    assert p.desired(1.5, start) == pytest.approx([0.2, 0.3])
    assert p.desired(9.0, start) == pytest.approx([0.3, 0.4])
    h = plan(points=((0.0, [0.0, 0.0], [0.0, 0.0]), (1.0, [1.0, 1.0], [0.0, 0.0])))
    assert h.desired(0.5, start) == pytest.approx([0.5, 0.5])  # smoothstep: half way at half time
    assert h.desired(0.25, start) == pytest.approx([0.15625, 0.15625])


def test_tolerances_per_joint_zero_is_the_default_negative_is_none():
    p = plan(path=(Tolerance("a", 0.05), Tolerance("b", -1.0)),
             goal=(Tolerance("b", 0.2), Tolerance("a", 0.0)), goal_time=0.5)
    assert p.path_tolerance[0] == 0.05 and math.isinf(p.path_tolerance[1])
    assert p.goal_tolerance.tolist() == [0.01, 0.2] and p.goal_time == 0.5
    assert p.off_path(np.array([0.1, 5.0]), np.array([0.0, 0.0])) == 0
    assert p.off_path(np.array([0.04, 5.0]), np.array([0.0, 0.0])) == -1
    assert p.off_goal(np.array([0.3, 0.55])) == []
    assert p.off_goal(np.array([0.32, 0.65])) == [0, 1]
