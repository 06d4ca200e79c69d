"""Per-axis laws as equations, velocity shaping, end conditions and the force-jump window."""

import pytest
from contact_control.axes import (
    END_FT_VIOLATION,
    END_MAX_TRAVEL,
    END_NONE,
    LAW_COMPLIANT_MOVE,
    LAW_FOLLOWER,
    LAW_SPRING,
)
from contact_control.laws import AxisLaw, ForceWindow, check_end, law_velocity, round_to, shape_velocity
from contact_control.params import AxisTuning

TUNING = AxisTuning()  # the fork's numbers
EXACT = AxisTuning(deadband=0.0, spring_rounding=0.0, spring_scale=1.0)  # the bare GCCF equations

FOLLOWER = AxisLaw(LAW_FOLLOWER, damping=30.0)
SPRING = AxisLaw(LAW_SPRING, damping=30.0, stiffness=100.0)
SPRING_OFFSET = AxisLaw(LAW_SPRING, damping=30.0, stiffness=100.0, offset=0.01)
MOVE = AxisLaw(LAW_COMPLIANT_MOVE, damping=30.0, velocity=0.05, max_travel=0.3)
MOVE_NO_B = AxisLaw(LAW_COMPLIANT_MOVE, damping=0.0, velocity=-0.05, force_limit=0.5)

EQUATIONS = [  # (law, tuning, force, travel, expected velocity)
    (FOLLOWER, EXACT, 6.0, 0.0, 6.0 / 30.0),  # V = F / b
    (FOLLOWER, EXACT, -3.0, 0.4, -3.0 / 30.0),  # travel does not matter
    (FOLLOWER, TUNING, 2.5, 0.0, 0.0),  # within the 2.5 N deadband
    (FOLLOWER, TUNING, -2.4, 0.0, 0.0),
    (FOLLOWER, TUNING, 2.6, 0.0, 2.6 / 30.0),
    (SPRING, EXACT, 10.0, 0.002, 10.0 / 30.0 - 100.0 * 0.002),  # V = F / b - k d
    (SPRING, EXACT, 0.0, -0.001, 0.1),  # released: back towards the start
    (SPRING_OFFSET, EXACT, 0.0, 0.0, -1.0),  # V = F / b - k (d + d_offset)
    (SPRING, TUNING, 10.0, 0.002, 0.2 * 0.13),  # fork: 0.2 * round(round(F) / b - k d, 0.01)
    (SPRING, TUNING, 0.004, 0.0, 0.0),
    (MOVE, EXACT, 0.0, 0.0, 0.05),  # V = V_desired + F / b
    (MOVE, EXACT, -0.9, 0.1, 0.05 - 0.03),  # opposing contact slows it
    (MOVE, EXACT, -1.5, 0.1, 0.0),  # and stops it
    (MOVE_NO_B, EXACT, 3.0, 0.0, -0.05),  # b = 0: no force term
    (MOVE, TUNING, 0.0, 0.29, 0.05 * 0.5),  # within 0.02 m of max travel: slows with remaining travel
    (MOVE, TUNING, 0.0, 0.2995, 0.02),  # never below the approach speed
    (AxisLaw(), EXACT, 50.0, 1.0, 0.0),  # none: still
]


@pytest.mark.parametrize(("law", "tuning", "force", "travel", "expected"), EQUATIONS)
def test_law_equations(law, tuning, force, travel, expected):
    assert law_velocity(law, tuning, force, travel) == pytest.approx(expected, abs=1e-9)


def test_round_to():
    assert round_to(0.3333, 0.01) == pytest.approx(0.33)
    assert round_to(0.3333, 0.0) == 0.3333


SHAPING = [  # (target, previous, dt, expected): defaults 0.005 min, 0.25 clamp, 2.5 m/s^2 both ways
    (0.005, 0.0, 0.002, 0.0),  # at most min velocity: zero
    (0.1, 0.0, 0.002, 0.005),  # accelerate by 2.5 m/s^2
    (0.1, 0.098, 0.002, 0.1),
    (1.0, 0.25, 0.002, 0.25),  # clamp to max_velocity
    (-1.0, -0.25, 0.002, -0.25),
    (0.0, 0.1, 0.002, 0.095),  # decelerate 0.005 per 2 ms cycle (the fork)
    (0.0, 0.003, 0.002, 0.0),
    (0.0, 0.1, 0.01, 0.075),  # slower cycles take bigger steps: the limit is per second
    (-0.1, 0.1, 0.002, -0.005),  # reversal: stop at once, then speed up the other way
]


@pytest.mark.parametrize(("target", "previous", "dt", "expected"), SHAPING)
def test_shape_velocity(target, previous, dt, expected):
    assert shape_velocity(target, previous, TUNING, dt) == pytest.approx(expected, abs=1e-12)


ENDS = [  # (law, force, travel, condition)
    (AxisLaw(LAW_FOLLOWER, damping=30, force_limit=5.0), 4.9, 0.0, END_NONE),
    (AxisLaw(LAW_FOLLOWER, damping=30, force_limit=5.0), -5.0, 0.0, END_FT_VIOLATION),
    (AxisLaw(LAW_FOLLOWER, damping=30), 500.0, 9.0, END_NONE),  # 0: no limits
    (MOVE, 0.0, 0.3, END_MAX_TRAVEL),
    (MOVE, 0.0, -0.31, END_MAX_TRAVEL),
    (AxisLaw(LAW_COMPLIANT_MOVE, velocity=0.1, force_limit=0.5, max_travel=0.3), 0.6, 0.4, END_FT_VIOLATION),
]


@pytest.mark.parametrize(("law", "force", "travel", "condition"), ENDS)
def test_end_conditions(law, force, travel, condition):
    assert check_end(law, force, travel) == condition


def test_force_window_spread_forgets_old_samples():
    w = ForceWindow(0.1)
    spreads = [w.add(t * 0.01, f) for t, f in enumerate([0, 1, 5, 2, 2, 2, 2, 2, 2, 2, 2, 2, 2, 2])]
    assert spreads[2] == 5.0 and spreads[3] == 5.0
    assert spreads[-1] == 0.0  # the 5 N peak left the 0.1 s window
