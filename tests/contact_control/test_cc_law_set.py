"""contact_control.law_set: six laws compiled once per request (no ROS)."""

from __future__ import annotations

import pytest
from contact_control.axes import (
    EXCEEDED_MOVE_AWAY,
    LAW_COMPLIANT_MOVE,
    LAW_FOLLOWER,
    LAW_FORCE_TRACKING,
    LAW_NONE,
    LAW_PATH,
    LAW_SPRING,
)
from contact_control.law_set import LawSet
from contact_control.laws import AxisLaw

NONE = AxisLaw()


def test_a_pressed_replay_compiles_to_its_axes_guards_and_path():
    """Path on X and Y, force tracking toward 10 N on Z with a limit, the rotations free."""
    path = AxisLaw(LAW_PATH, stiffness=5.0, max_travel=0.03)
    press = AxisLaw(LAW_FORCE_TRACKING, damping=800.0, target=10.0, velocity=0.005, force_limit=20.0,
                    exceeded_action=EXCEEDED_MOVE_AWAY)
    s = LawSet.of([path, path, press, NONE, NONE, NONE], diff_max=(0.0, 0.0, 5.0, 0.0, 0.0, 0.0),
                  fast_guard=True)
    assert s.active == (0, 1, 2) and s.path_axes == (0, 1) and s.watched == (2,)
    assert s.types == (LAW_PATH, LAW_PATH, LAW_FORCE_TRACKING, LAW_NONE, LAW_NONE, LAW_NONE)
    assert s.actions == (-1, -1, EXCEEDED_MOVE_AWAY, -1, -1, -1)  # only a limited axis has an action
    assert s.diff_axes == (2,)
    assert s.guarded == (False, False, True, False, False, False)
    assert s.floor == (False, False, False, True, True, True)  # no minimum velocity on a path or a press
    assert s.needs_travel  # the path law has a max travel
    assert not LawSet.of([press] + [NONE] * 5, (0.0,) * 6, fast_guard=False).guarded[0]
    # the press integrates beside the path; alone it stays proportional
    assert s.integrating == (False, False, True, False, False, False)
    assert not any(LawSet.of([NONE, NONE, press, NONE, NONE, NONE], (0.0,) * 6, fast_guard=True).integrating)


@pytest.mark.parametrize(("law", "travel"), [
    (AxisLaw(LAW_FOLLOWER, damping=30.0), False),
    (AxisLaw(LAW_FOLLOWER, damping=30.0, max_travel=0.1), True),
    (AxisLaw(LAW_SPRING, damping=3.0, stiffness=10.0), True),
    (AxisLaw(LAW_COMPLIANT_MOVE, velocity=0.01), True),
    (AxisLaw(LAW_FORCE_TRACKING, damping=800.0, target=5.0), False),
])
def test_travel_is_needed_by_the_laws_that_measure_it(law, travel):
    assert LawSet.of([law] + [NONE] * 5, (0.0,) * 6, fast_guard=False).needs_travel is travel


def test_a_lowered_gain_keeps_the_law_type_and_the_rest_of_the_set():
    spring = AxisLaw(LAW_SPRING, damping=3.0, stiffness=10.0)
    s = LawSet.of([spring] + [NONE] * 5, (0.0,) * 6, fast_guard=False)
    lower = AxisLaw(LAW_SPRING, damping=6.0, stiffness=5.0)
    t = s.with_law(0, lower)
    assert t.laws[0] == lower and s.laws[0] == spring  # a new set; the old one is unchanged
    assert (t.types, t.active, t.watched) == (s.types, s.active, s.watched)
    with pytest.raises(AssertionError):
        s.with_law(0, AxisLaw(LAW_FOLLOWER, damping=30.0))
