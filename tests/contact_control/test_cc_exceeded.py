"""Exceeded actions after a compliant move meets an obstacle: stop, move away, gravity compensation.

The obstacle is a stiff wall (20 N/mm, a position-controlled arm against a table) 1 cm below the start, and
the simulated arm follows each command 20 ms late, so the move overshoots the 0.5 N limit into the wall as a
real arm does (the thesis demo on the simulated UR5 kept pressing with 9 N).
"""

from dataclasses import replace

import numpy as np
import pytest
from cc_sim import DT, ClosedLoop, controller, laws
from contact_control.axes import (
    END_FT_VIOLATION,
    EXCEEDED_GRAVITY_COMPENSATION,
    EXCEEDED_MOVE_AWAY,
    EXCEEDED_STOP,
    LAW_COMPLIANT_MOVE,
    LAW_FOLLOWER,
    SAFETY_OVER_LIMIT,
)
from contact_control.laws import AxisLaw

LIMIT = 0.5  # [N], the thesis's max force
WALL_Z = -0.01  # [m]
STIFFNESS = 20000.0  # [N/m]


def wall_force(pose: np.ndarray) -> float:
    """Force of the wall on the tool along +Z [N] (it pushes up once the tool is below WALL_Z)."""
    depth = WALL_Z - pose[2, 3]
    return STIFFNESS * depth if depth > 0.0 else 0.0


def wrench(push=(0.0, 0.0, 0.0)):
    """The wall's force plus a constant push (x, y, z) [N]."""

    def w(t, pose):
        return [push[0], push[1], push[2] + wall_force(pose), 0.0, 0.0, 0.0]

    return w


def approach(action: int, **params) -> ClosedLoop:
    """A compliant move down onto the wall (b = 30, -0.01 m/s, max force 0.5 N), run for 3 s."""
    loop = ClosedLoop(controller(**params), lag=0.02)
    move = AxisLaw(LAW_COMPLIANT_MOVE, damping=30.0, velocity=-0.01, force_limit=LIMIT)
    loop.start(laws(z=replace(move, exceeded_action=action)))
    loop.run(wrench(), 3.0)
    assert loop.results[-1].end_conditions[2] == END_FT_VIOLATION and not loop.results[-1].move_active
    return loop


def test_stop_keeps_pressing_on_the_obstacle():
    loop = approach(EXCEEDED_STOP)
    assert wall_force(loop.pose) > 2 * LIMIT  # the standing press move_away exists for
    assert not loop.results[-1].commanding


def test_move_away_backs_off_until_the_force_is_below_the_limit_then_holds():
    loop = approach(EXCEEDED_MOVE_AWAY)
    ended = next(i for i, r in enumerate(loop.results) if not r.move_active)
    peak = max(r.wrench[2] for r in loop.results)
    assert peak > LIMIT  # it did press
    v = loop.velocities()[ended:, 2]
    assert v.max() > 0.0 and v.max() <= 0.01 + 1e-12  # backed off upward, at move_away_velocity at most
    assert v.min() >= 0.0  # never pressed further after the limit
    final = loop.results[-1]
    assert wall_force(loop.pose) < 0.5 * LIMIT and abs(final.wrench[2]) < LIMIT
    assert not final.commanding and np.all(v[-100:] == 0.0)  # holds afterwards, no twists due
    assert loop.pose[2, 3] - WALL_Z < 0.002  # backed off only as far as needed (2 mm at most)
    assert "moved away" in final.message and loop.ctrl.move_outcome(loop.ctrl.move_id) is True


def test_blocking_outcome_waits_until_the_press_is_released():
    ctrl = controller()
    loop = ClosedLoop(ctrl, lag=0.02)
    loop.start(laws(z=AxisLaw(LAW_COMPLIANT_MOVE, velocity=-0.01, force_limit=LIMIT, exceeded_action=1)))
    outcomes = []
    for _ in range(1500):
        loop.run(wrench(), DT)
        r = loop.results[-1]
        outcomes.append((r.move_active, any(r.reacting), ctrl.move_outcome(ctrl.move_id)))
    backing_off = [o for o in outcomes if not o[0] and o[1]]
    assert backing_off and all(o[2] is None for o in backing_off)
    assert outcomes[-1] == (False, False, True)


def test_move_away_gives_up_after_its_max_distance_when_the_force_stays():
    # A contact that follows the arm (or a sensor bias): |F| never drops, the arm must not back off forever.
    loop = ClosedLoop(controller(move_away_max_distance=0.005), lag=0.02)
    loop.start(laws(z=AxisLaw(LAW_COMPLIANT_MOVE, velocity=-0.01, force_limit=LIMIT, exceeded_action=1)))
    loop.run(lambda t, pose: [0, 0, 0.0 if t < 0.6 else 1.0, 0, 0, 0], 3.0)
    final = loop.results[-1]
    assert not final.commanding and "maximum" in final.message
    assert loop.pose[2, 3] == pytest.approx(-0.01 * 0.6 + 0.005, abs=0.001)  # 5 mm up from where it ended


def test_gravity_compensation_yields_to_a_push_after_the_limit():
    loop = approach(EXCEEDED_GRAVITY_COMPENSATION)
    result = loop.results[-1]
    assert result.commanding and result.reacting[2] and result.laws[2] == LAW_FOLLOWER
    rest = loop.pose[2, 3]
    loop.run(wrench(push=(6.0, 0.0, 0.0)), 0.5)  # a push along X, which has no law: nothing moves
    assert loop.pose[2, 3] == pytest.approx(rest) and loop.pose[0, 3] == 0.0
    loop.run(wrench(push=(0.0, 0.0, 6.0)), 1.0)  # a 6 N lift: follows at F / b = 0.2 m/s
    assert loop.velocities()[-1, 2] == pytest.approx(6.0 / 30.0)
    assert loop.pose[2, 3] > rest + 0.1
    loop.run(wrench(), 0.5)  # released: stays (follower deadband)
    assert loop.velocities()[-1, 2] == 0.0 and loop.results[-1].commanding


def test_stop_a_new_request_and_a_safety_trip_end_the_exceeded_action():
    loop = approach(EXCEEDED_GRAVITY_COMPENSATION)
    assert loop.ctrl.stop("stop service")
    loop.run(wrench(push=(0.0, 0.0, 6.0)), 0.2)
    assert not loop.results[-1].commanding and loop.velocities()[-1, 2] == 0.0
    assert "stop service" in loop.results[-1].message
    loop = approach(EXCEEDED_GRAVITY_COMPENSATION)
    loop.run(wrench(push=(0.0, 0.0, 40.0)), 0.2)  # over the global limit: latched, nothing moves
    assert loop.results[-1].safety == SAFETY_OVER_LIMIT and not loop.results[-1].commanding
    assert loop.ctrl.reset_safety()
    loop.run(wrench(push=(0.0, 0.0, 6.0)), 0.2)
    assert loop.velocities()[-1, 2] == 0.0
    loop = approach(EXCEEDED_GRAVITY_COMPENSATION)
    loop.start(laws(x=AxisLaw(LAW_FOLLOWER, damping=30.0)))
    loop.run(wrench(push=(0.0, 0.0, 6.0)), 0.2)
    assert loop.velocities()[-1, 2] == 0.0 and not any(loop.results[-1].reacting)


def test_exceeded_action_pauses_on_stale_data_and_ends_after_the_no_data_timeout():
    loop = approach(EXCEEDED_GRAVITY_COMPENSATION, wrench_timeout=0.1, no_data_end_timeout=0.5)
    held = loop.ctrl.check_stale(loop.t + 0.2)
    assert held.velocity == [0.0] * 6 and held.commanding
    ended = loop.ctrl.check_stale(loop.t + 0.7)
    assert not ended.commanding and "no wrench" in ended.message
