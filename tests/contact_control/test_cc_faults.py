"""ContactControl under a real cell's faults: future stamps, clock jumps, re-sent and changed requests."""

import numpy as np
import pytest
from cc_sim import DT, ClosedLoop, controller, laws
from contact_control.axes import (
    LAW_COMPLIANT_MOVE,
    LAW_FOLLOWER,
    LAW_SPRING,
    SAFETY_NAN,
    SAFETY_OK,
    SAFETY_STALE,
)
from contact_control.laws import AxisLaw

FOLLOWER = AxisLaw(LAW_FOLLOWER, damping=30.0)
PUSH_Z = [0.0, 0.0, 5.0, 0.0, 0.0, 0.0]


def test_a_wrench_stamped_in_the_future_is_refused_like_nan_then_good_data_resumes():
    ctrl = controller(future_stamp_tolerance=0.1, lp_filter_enabled=False)
    ctrl.set_laws(laws(z=FOLLOWER), np.eye(4), 0.0)
    for k in range(200):
        ctrl.update(PUSH_Z, k * DT, stamp=k * DT)
    assert ctrl.last_result.velocity[2] > 0.1
    held = ctrl.update(PUSH_Z, 0.4, stamp=0.4 + 5.0)
    assert held.velocity == [0.0] * 6 and held.safety == SAFETY_NAN
    assert "in the future" in held.message or "ahead" in held.message
    assert ctrl.check_stale(0.41) is None  # refused data still counts as data: no stale zeros on top
    assert ctrl.update(PUSH_Z, 0.402, stamp=0.402 + 0.05).safety == SAFETY_OK  # within the tolerance
    assert ctrl.move_active


def test_future_stamps_are_accepted_when_stamp_checks_are_off():
    ctrl = controller(check_stamp_age=False)
    ctrl.set_laws(laws(z=FOLLOWER), np.eye(4), 0.0)
    assert ctrl.update(PUSH_Z, 0.0, stamp=100.0).safety == SAFETY_OK


def test_a_clock_jump_halts_resets_the_timing_and_the_move_resumes_with_fresh_data():
    ctrl = controller(lp_filter_enabled=False, wrench_timeout=0.1, no_data_end_timeout=1.0)
    ctrl.set_laws(laws(z=FOLLOWER), np.eye(4), 100.0)
    for k in range(300):
        ctrl.update(PUSH_Z, 100.0 + k * DT, stamp=100.0 + k * DT)
    assert ctrl.last_result.velocity[2] > 0.1
    held = ctrl.clock_jumped(10.0, "clock jumped back by 90.6 s")
    assert held.velocity == [0.0] * 6 and held.safety == SAFETY_STALE and "clock jumped" in held.message
    # Until data stamped after the jump arrives the output stays zero (it looks stale, not fresh) ...
    assert ctrl.check_stale(10.05).velocity == [0.0] * 6
    # ... data stamped before the jump is refused (it lies in the future now) ...
    assert ctrl.update(PUSH_Z, 10.06, stamp=100.7).velocity == [0.0] * 6
    # ... and fresh data resumes the same move; the no-data end timeout restarted at the jump.
    assert ctrl.move_active
    for k in range(200):
        result = ctrl.update(PUSH_Z, 10.1 + k * DT, stamp=10.1 + k * DT)
    assert result.velocity[2] > 0.1 and ctrl.move_active


def follow_with_requests(period: float | None, seconds: float = 2.0, change=None) -> tuple[float, np.ndarray]:
    """Follower on Z under a 5 N push; the same request re-sent every `period` s (None: never), or `change`
    (a function of the request count) sent instead. Returns (Z travel, velocity history)."""
    loop = ClosedLoop(controller(lp_filter_enabled=False))
    loop.start(laws(z=FOLLOWER))
    count, next_t = 0, period
    while loop.t < seconds:
        loop.run(PUSH_Z, DT)
        if period is not None and loop.t >= next_t:
            count += 1
            request = change(count) if change else laws(z=FOLLOWER)
            loop.ctrl.set_laws(request, None, loop.t)
            next_t += period
    return loop.pose[2, 3], loop.velocities()


def test_a_request_re_sent_at_100_hz_changes_nothing():
    quiet, _ = follow_with_requests(None)
    spammed, velocities = follow_with_requests(0.01)
    assert quiet > 0.2  # 5 N / 30 = 0.167 m/s, less the speed-up
    assert spammed == pytest.approx(quiet, rel=0.10)
    assert np.all(velocities[len(velocities) // 4 :, 2] > 0.15)  # never back to rest


def test_a_request_keeping_the_law_changes_parameters_from_the_current_velocity():
    def damping(count: int):
        return laws(z=AxisLaw(LAW_FOLLOWER, damping=30.0 if count % 2 else 31.0))

    quiet, _ = follow_with_requests(None)
    changing, velocities = follow_with_requests(0.01, change=damping)
    assert changing == pytest.approx(quiet, rel=0.10)
    steps = np.abs(np.diff(velocities[:, 2]))
    assert steps.max() <= 2.5 * DT + 1e-9  # within the default acceleration limit: never from rest


def test_only_the_axis_whose_law_changes_starts_from_rest():
    ctrl = controller(lp_filter_enabled=False)
    loop = ClosedLoop(ctrl)
    loop.start(laws(x=FOLLOWER, z=FOLLOWER))
    push = [5.0, 0.0, 5.0, 0.0, 0.0, 0.0]
    loop.run(push, 1.0)
    vx, vz = loop.results[-1].velocity[0], loop.results[-1].velocity[2]
    assert vx > 0.1 and vz > 0.1
    spring = AxisLaw(LAW_SPRING, damping=30.0, stiffness=10.0)
    first_id = ctrl.move_id
    new_id = ctrl.set_laws(laws(x=spring, z=FOLLOWER), None, loop.t)
    assert new_id != first_id and ctrl.move_active
    result = loop.run(push, DT)
    assert result.velocity[2] == pytest.approx(vz, abs=0.01)  # Z kept going
    assert abs(result.velocity[0]) < 0.02  # X restarted from rest
    assert abs(result.travel[0]) < 1e-3  # and measures its travel from here (the spring's rest point)


def test_a_request_with_a_different_law_everywhere_still_starts_from_rest():
    ctrl = controller(lp_filter_enabled=False)
    loop = ClosedLoop(ctrl)
    loop.start(laws(z=FOLLOWER))
    loop.run(PUSH_Z, 1.0)
    move = AxisLaw(LAW_COMPLIANT_MOVE, damping=0.0, velocity=0.05)
    ctrl.set_laws(laws(z=move), None, loop.t)
    assert loop.run(PUSH_Z, DT).velocity[2] < 0.01


def test_a_law_set_before_the_sim_clock_runs_waits_for_data_instead_of_ending():
    """`rosbag play --clock` with use_sim_time: the law is set while the clock still reads 0; when the bag's
    clock appears (1.7e9 s) the move must not end at once for "no data since the start"."""
    ctrl = controller(lp_filter_enabled=False, wrench_timeout=0.1, no_data_end_timeout=1.0)
    ctrl.set_laws(laws(z=FOLLOWER), np.eye(4), 0.0)
    t0 = 1.7e9
    held = ctrl.check_stale(t0)
    assert held.velocity == [0.0] * 6 and ctrl.move_active
    assert ctrl.check_stale(t0 + 0.5) is not None and ctrl.move_active  # still waiting, within the timeout
    for k in range(300):
        ctrl.update(PUSH_Z, t0 + 0.6 + k * DT, stamp=t0 + 0.6 + k * DT)
    assert ctrl.last_result.velocity[2] > 0.1 and ctrl.move_active
