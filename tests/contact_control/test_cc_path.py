"""The path law (LAW_PATH, contact_control.path_ref): a moving reference followed with its velocity fed
forward, compliant to a push, ending when the reference stops coming or the error grows too large."""

from __future__ import annotations

import numpy as np
import pytest
from contact_control.axes import END_PATH_ERROR, END_PATH_LOST, LAW_PATH
from contact_control.laws import AxisLaw
from contact_control.request import (
    RequestError,
    empty_laws_request,
    empty_request,
    validate_laws_request,
    validate_request,
)

from .cc_sim import DT, ClosedLoop, controller, laws

SPEED = 0.02  # [m/s] along X


def path(k: float = 5.0, b: float = 0.0, max_error: float = 0.0) -> list[AxisLaw]:
    return laws(x=AxisLaw(LAW_PATH, damping=b, stiffness=k, max_travel=max_error),
                y=AxisLaw(LAW_PATH, damping=b, stiffness=k), z=AxisLaw(LAW_PATH, damping=b, stiffness=k))


def feed(loop: ClosedLoop, x0: float, t0: float):
    """A reference moving along +X at SPEED from x0 at t0, sent every cycle."""

    def wrench(t, pose):
        x = x0 + SPEED * (t - t0)
        loop.ctrl.set_path_reference((x, 0.0, 0.0), (0, 0, 0, 1), (SPEED, 0, 0, 0, 0, 0), t)
        return (0.0,) * 6

    return wrench


def test_a_moving_reference_is_followed_within_a_fraction_of_a_millimetre():
    ctrl = controller(lp_filter_enabled=False, acceleration_linear=0.4)
    loop = ClosedLoop(ctrl, lag=0.02)
    ctrl.set_path_reference((0, 0, 0), (0, 0, 0, 1), (0,) * 6, 0.0)
    loop.start(path())
    result = loop.run(feed(loop, 0.0, 0.0), 3.0)
    assert result.move_active and result.laws[0] == LAW_PATH
    x_ref = SPEED * loop.t
    assert loop.pose[0, 3] == pytest.approx(x_ref, abs=3e-4)  # 20 ms of lag, fed forward: ~0.1 mm behind
    assert abs(loop.pose[1, 3]) < 1e-6 and abs(loop.pose[2, 3]) < 1e-6
    assert result.velocity[0] == pytest.approx(SPEED, abs=1e-3)


def test_an_offset_start_converges_at_the_gain_and_a_push_gives_way_when_b_is_set():
    ctrl = controller(lp_filter_enabled=False)
    loop = ClosedLoop(ctrl)
    ctrl.set_path_reference((0.01, 0, 0), (0, 0, 0, 1), (0,) * 6, 0.0)
    loop.start(path(k=5.0, b=100.0))

    def hold(t, pose, push=0.0):
        ctrl.set_path_reference((0.01, 0, 0), (0, 0, 0, 1), (0,) * 6, t)
        return (0.0, push, 0.0, 0.0, 0.0, 0.0)

    loop.run(hold, 2.0)
    assert loop.pose[0, 3] == pytest.approx(0.01, abs=2e-4)
    loop.run(lambda t, pose: hold(t, pose, 10.0), 2.0)  # 10 N along +Y: equilibrium F / (b k) = 20 mm
    assert loop.pose[1, 3] == pytest.approx(10.0 / (100.0 * 5.0), abs=2e-3)
    loop.run(hold, 3.0)  # released: back on the path
    assert abs(loop.pose[1, 3]) < 5e-4


def test_a_reference_that_stops_coming_stops_the_tool_near_its_last_point():
    """A replay that stalls for 0.35 s at 0.1 m/s (a loaded machine's stall; under the timeout): the move goes
    on, and the tool stops within v x path_extrapolate (5 mm) of the last reference instead of running v / k
    (20 mm) past it."""
    ctrl = controller(lp_filter_enabled=False, acceleration_linear=2.5, deceleration_linear=2.5)
    loop = ClosedLoop(ctrl, lag=0.02)
    ctrl.set_path_reference((0, 0, 0), (0, 0, 0, 1), (0,) * 6, 0.0)
    loop.start(path())
    speed, sent = 0.1, [0.0]

    def until(stall: float):
        def wrench(t, pose):
            if t < stall:
                sent[0] = speed * t
                ctrl.set_path_reference((sent[0], 0, 0), (0, 0, 0, 1), (speed, 0, 0, 0, 0, 0), t)
            return (0.0,) * 6
        return wrench

    loop.run(until(1.0), 1.0)
    assert loop.pose[0, 3] == pytest.approx(speed * loop.t, abs=2e-3)  # following before the stall
    result = loop.run(until(1.0), 0.35)
    assert result.move_active
    past = loop.pose[0, 3] - sent[0]
    assert past < speed * 0.05 + 1e-3, f"{past * 1e3:.1f} mm past the last reference"


def test_a_stalled_reference_with_a_horizon_is_followed_along_it_then_stands_at_its_end():
    """The same 0.1 m/s stream with 0.3 s of horizon (a pose every 20 ms, turning about Z at 0.2 rad/s): a
    0.2 s stall keeps the tool moving on the path (it stopped without one, above); a 0.4 s stall ends at the
    horizon's last pose, not v / k past it."""
    ctrl = controller(lp_filter_enabled=False, acceleration_linear=2.5, deceleration_linear=2.5)
    loop = ClosedLoop(ctrl, lag=0.02)
    speed, turn, step = 0.1, 0.2, 0.02

    def pose_at(t):
        return (speed * t, 0.0, 0.0), (0.0, 0.0, np.sin(turn * t / 2), np.cos(turn * t / 2))

    def send(t):
        p, q = pose_at(t)
        horizon = [pose_at(t + (j + 1) * step) for j in range(15)]
        assert ctrl.set_path_reference(p, q, (speed, 0, 0, 0, 0, turn), t, horizon, step) == ""

    def until(stop: float):
        def wrench(t, pose):
            if t < stop:
                send(t)
            return (0.0,) * 6
        return wrench

    send(0.0)
    loop.start(laws(x=AxisLaw(LAW_PATH, stiffness=5.0), y=AxisLaw(LAW_PATH, stiffness=5.0),
                    z=AxisLaw(LAW_PATH, stiffness=5.0), rz=AxisLaw(LAW_PATH, stiffness=5.0)))
    loop.run(until(1.0), 1.0)
    result = loop.run(until(1.0), 0.2)  # stalled: the horizon carries the reference on
    assert result.move_active
    assert loop.pose[0, 3] == pytest.approx(speed * loop.t, abs=3e-3)
    assert result.velocity[0] == pytest.approx(speed, abs=0.01)
    assert result.velocity[5] == pytest.approx(turn, abs=0.05)
    loop.run(until(1.0), 0.3)  # past the horizon (0.3 s): stands at its last pose
    end = speed * (1.0 + 15 * step)
    assert loop.pose[0, 3] == pytest.approx(end, abs=2e-3)
    assert np.arctan2(loop.pose[1, 0], loop.pose[0, 0]) == pytest.approx(turn * (1.0 + 15 * step), abs=0.02)


def test_a_bad_horizon_is_refused_and_changes_nothing():
    ctrl = controller(lp_filter_enabled=False)
    assert ctrl.set_path_reference((0, 0, 0), (0, 0, 0, 1), (0,) * 6, 0.0) == ""
    ahead = [((0.01, 0, 0), (0, 0, 0, 1))]
    assert "horizon_step > 0" in ctrl.set_path_reference((1, 0, 0), (0, 0, 0, 1), (0,) * 6, 0.1, ahead, 0.0)
    assert "unit quaternion" in ctrl.set_path_reference((1, 0, 0), (0, 0, 0, 1), (0,) * 6, 0.1,
                                                        [((0, 0, 0), (0, 0, 0, 2))], 0.02)
    assert "finite" in ctrl.set_path_reference((1, 0, 0), (0, 0, 0, 1), (0,) * 6, 0.1,
                                               [((np.nan, 0, 0), (0, 0, 0, 1))], 0.02)
    error, velocity = [0.0] * 6, [0.0] * 6
    assert ctrl._path.error(0.01, np.eye(4), None, error, velocity)
    assert error == [0.0] * 6  # still the first reference, at the origin


def test_the_move_ends_when_the_reference_stops_coming_or_the_error_grows_too_large():
    ctrl = controller(lp_filter_enabled=False, path_reference_timeout=0.1)
    loop = ClosedLoop(ctrl)
    ctrl.set_path_reference((0, 0, 0), (0, 0, 0, 1), (0,) * 6, 0.0)
    loop.start(path())
    result = loop.run((0.0,) * 6, 0.2)  # nobody sends: lost after 0.1 s
    assert not result.move_active and result.end_conditions[0] == END_PATH_LOST
    assert "no ~path_reference for" in ctrl.end_message

    ctrl = controller(lp_filter_enabled=False)
    loop = ClosedLoop(ctrl)
    ctrl.set_path_reference((0, 0, 0), (0, 0, 0, 1), (0,) * 6, 0.0)
    loop.start(path(max_error=0.005))

    def jump(t, pose):  # the reference runs away at 0.1 m/s while the arm is held (lag of a blocked tool)
        ctrl.set_path_reference((0.1 * t, 0, 0), (0, 0, 0, 1), (0,) * 6, t)
        return (0.0,) * 6

    result = loop.run(jump, 0.5)
    assert not result.move_active and result.end_conditions[0] == END_PATH_ERROR
    assert "from the path reached max_travel 0.005" in ctrl.end_message


def test_a_move_set_before_its_first_reference_stands_still_for_the_timeout_then_follows_or_ends():
    """A sender publishes its first reference and then calls ConfigureLaws; the topic may deliver it after
    the call (or connect a moment later): the move waits for it, standing still, instead of ending."""
    ctrl = controller(lp_filter_enabled=False, path_reference_timeout=0.3)
    loop = ClosedLoop(ctrl)
    loop.start(path())
    result = loop.run((0.0,) * 6, 0.2)  # nothing yet: the tool holds still
    assert result.move_active and np.allclose(loop.pose[:3, 3], 0.0, atol=1e-9)
    t0 = loop.t
    result = loop.run(feed(loop, 0.0, t0), 1.0)
    assert result.move_active and loop.pose[0, 3] == pytest.approx(SPEED * (loop.t - t0), abs=1e-3)

    ctrl = controller(lp_filter_enabled=False, path_reference_timeout=0.3)
    loop = ClosedLoop(ctrl)
    loop.start(path())
    result = loop.run((0.0,) * 6, 0.5)  # none within the timeout: lost
    assert not result.move_active and result.end_conditions[0] == END_PATH_LOST
    assert "no ~path_reference received" in ctrl.end_message


def test_orientation_error_is_a_rotation_vector_along_the_control_axes():
    ctrl = controller(lp_filter_enabled=False)
    pose = np.eye(4)
    turned = (0.0, 0.0, np.sin(0.05), np.cos(0.05))  # 0.1 rad about Z
    ctrl.set_path_reference((0, 0, 0), turned, (0,) * 6, 0.0)
    ctrl.set_laws(laws(rz=AxisLaw(LAW_PATH, stiffness=2.0)), pose, 0.0)
    result = None
    for i in range(50):
        result = ctrl.update((0.0,) * 6, (i + 1) * DT, eef_pose=pose)
    assert result is not None and result.velocity[5] == pytest.approx(0.2, abs=1e-6)  # k e = 2 x 0.1


def test_requests_path_through_configure_laws_only_with_a_gain():
    req = empty_laws_request()
    req.x.law, req.x.stiffness, req.x.damping, req.x.max_travel = 5, 4.0, 200.0, 0.02
    (x, *_rest) = validate_laws_request(req)
    assert x.law == LAW_PATH and x.stiffness == 4.0 and x.max_travel == 0.02
    req.x.stiffness = 0.0
    with pytest.raises(RequestError, match="path gain k"):
        validate_laws_request(req)
    old = empty_request()
    old.direction_control_laws.x.type = 5
    with pytest.raises(RequestError, match="ConfigureLaws only"):
        validate_request(old)
