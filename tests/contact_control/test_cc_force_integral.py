"""contact_control.force_integral: force tracking's integral term beside a path law (no ROS)."""

from __future__ import annotations

import pytest
from contact_control.axes import LAW_FORCE_TRACKING, LAW_PATH
from contact_control.force_integral import ForceIntegral
from contact_control.law_set import LawSet
from contact_control.laws import AxisLaw
from contact_control.params import load_settings

TUNING = load_settings({}).tuning(False)  # T_i 1 s, deadband 0.2 N, contact fraction 0.5
PATH = AxisLaw(LAW_PATH, stiffness=5.0)
PRESS = AxisLaw(LAW_FORCE_TRACKING, damping=2000.0, velocity=0.005, target=-10.0)  # reads -F pressing


def beside_a_path() -> LawSet:
    return LawSet.of([PATH, PATH, PRESS, AxisLaw(), AxisLaw(), AxisLaw()], (0.0,) * 6, fast_guard=False)


def test_the_term_integrates_the_error_outside_the_deadband_and_stops_at_the_approach_speed():
    term = ForceIntegral()
    # 4 N short of the target, 3.8 N outside the 0.2 N deadband, for 1 s: 3.8 N / (b T_i) x 1 s
    for _ in range(500):
        v = term.step(2, PRESS, TUNING, -6.0, 0.002)
    assert v == pytest.approx(3.8 / 2000.0, rel=1e-6)
    assert term.step(2, PRESS, TUNING, -10.1, 0.002) == v  # inside the deadband it holds
    for _ in range(20000):
        v = term.step(2, PRESS, TUNING, -6.0, 0.002)
    assert v == pytest.approx(PRESS.velocity)  # capped: never a second approach
    assert term.step(2, PRESS, TUNING, -4.0, 0.002) == 0.0  # out of contact (short of half the target)
    assert term.step(2, PRESS, TUNING, -6.0, 0.002) == pytest.approx(3.8 * 0.002 / 2000.0)  # from zero


def test_new_laws_keep_the_term_of_an_axis_that_keeps_integrating_and_a_new_move_starts_from_zero():
    term, laws = ForceIntegral(), beside_a_path()
    assert laws.integrating[2]
    for _ in range(100):
        term.step(2, PRESS, TUNING, -6.0, 0.002)
    kept = term.velocity(2, laws, TUNING, 0.0, -10.0, -10.0, 0.002)
    assert kept > 0.0
    term.adopt(laws, fresh=False)  # a bumpless change: the same press beside the path
    assert term.velocity(2, laws, TUNING, 0.0, -10.0, -10.0, 0.002) == kept
    alone = LawSet.of([AxisLaw(), AxisLaw(), PRESS, AxisLaw(), AxisLaw(), AxisLaw()], (0.0,) * 6, False)
    term.adopt(alone, fresh=False)  # the path ended: no term, and none left for later
    assert term.velocity(2, alone, TUNING, 0.0, -6.0, -6.0, 0.002) == 0.0
    term.adopt(laws, fresh=False)
    assert term.velocity(2, laws, TUNING, 0.0, -10.0, -10.0, 0.002) == 0.0
    for _ in range(100):
        term.step(2, PRESS, TUNING, -6.0, 0.002)
    term.adopt(laws, fresh=True)
    assert term.velocity(2, laws, TUNING, 0.0, -10.0, -10.0, 0.002) == 0.0


def test_the_pressing_guard_still_caps_what_the_term_adds():
    term = ForceIntegral()
    guarded = LawSet.of([PATH, PATH, PRESS, AxisLaw(), AxisLaw(), AxisLaw()], (0.0,) * 6, fast_guard=True)
    for _ in range(2000):
        term.step(2, PRESS, TUNING, -6.0, 0.002)
    # the unfiltered force is past the target: no pressing, whatever the filtered force and the term say
    assert term.velocity(2, guarded, TUNING, 0.001, -6.0, -12.0, 0.002) == 0.0
