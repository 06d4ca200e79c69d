"""contact_control.ends: force limits armed after a start and counted over samples, max travel, force jumps,
and the end's reason in words."""

from __future__ import annotations

import math

from contact_control.axes import End, Law
from contact_control.ends import EndChecks, end_reason
from contact_control.law_set import LawSet
from contact_control.laws import AxisLaw

PRESS = AxisLaw(Law.FOLLOWER, damping=100.0, force_limit=10.0, max_travel=0.05)


def laws_on_z(law: AxisLaw, diff: float = 0.0) -> LawSet:
    return LawSet.of([AxisLaw()] * 2 + [law] + [AxisLaw()] * 3, [diff] * 6, fast_guard=False)


def test_a_force_limit_counts_once_armed_and_after_its_samples_in_a_row():
    ends = EndChecks([0.0] * 6, window=0.1, arm_time=0.5, limit_samples=2)
    laws, travel, over = laws_on_z(PRESS), [0.0] * 6, [0.0, 0.0, 12.0, 0.0, 0.0, 0.0]
    ends.restart(0.0)
    assert ends.check(0.1, laws, over, travel) == (-1, End.NONE)  # speeding up: not armed yet
    ends.arm(0.5)
    assert ends.check(0.5, laws, over, travel) == (-1, End.NONE)  # one sample over: a spike
    assert ends.check(0.502, laws, [0.0] * 6, travel) == (-1, End.NONE)  # and it was
    assert ends.check(0.504, laws, over, travel) == (-1, End.NONE)
    assert ends.check(0.506, laws, over, travel) == (2, End.FT_VIOLATION)
    ends.held(1.0)  # a hold disarms: the speed-up after it is a new start
    assert ends.check(1.1, laws, over, travel) == (-1, End.NONE)


def test_max_travel_and_a_force_jump_end_the_move_on_their_axis():
    ends = EndChecks([0.0, 0.0, 3.0, 0.0, 0.0, 0.0], window=0.1, arm_time=0.0, limit_samples=1)
    laws = laws_on_z(AxisLaw(Law.FOLLOWER, damping=100.0, max_travel=0.05), diff=3.0)
    assert ends.check(0.0, laws, [0.0] * 6, [0.0, 0.0, 0.06, 0.0, 0.0, 0.0]) == (2, End.MAX_TRAVEL)
    ends.restart(0.0)
    assert ends.check(0.00, laws, [0.0] * 6, [0.0] * 6) == (-1, End.NONE)
    assert ends.check(0.05, laws, [0.0, 0.0, 4.0, 0.0, 0.0, 0.0], [0.0] * 6) == (2, End.DIFF_VIOLATION)
    ends.restart(0.2)  # a new move forgets the window
    assert ends.check(0.25, laws, [0.0, 0.0, 4.0, 0.0, 0.0, 0.0], [0.0] * 6) == (-1, End.NONE)


def test_the_reason_names_the_axis_the_condition_and_the_numbers():
    kw = {"force": 20.31, "travel": 0.05, "path_error": 0.031, "path_age": math.inf, "path_timeout": 0.5,
          "diff": 3.0}
    limit = AxisLaw(Law.FOLLOWER, damping=100.0, force_limit=20.0, max_travel=0.03)
    assert end_reason(1, End.FT_VIOLATION, limit, **kw) == \
        "axis y: force/torque limit: |20.3| reached the limit 20.0"
    assert "no ~path_reference received" in end_reason(0, End.PATH_LOST, limit, **kw)
    assert "no ~path_reference for 0.70 s" in end_reason(0, End.PATH_LOST, limit, **{**kw, "path_age": 0.7})
    assert "|0.031| m from the path reached max_travel 0.03" in end_reason(2, End.PATH_ERROR, limit, **kw)
    assert "rad from the path" in end_reason(4, End.PATH_ERROR, limit, **kw)
    assert "travel |0.05| reached the max path deviation 0.03" in end_reason(2, End.MAX_TRAVEL, limit, **kw)
