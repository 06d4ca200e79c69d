"""Safety behaviour: singularities, joint limits, stale and invalid commands, pause, bad joint states."""

from __future__ import annotations

import math

import numpy as np
import pytest
from jog_arm_testing import PerfectArm, Robot, Trace, make_jog

from jog_arm import StatusCode


def assert_within_joint_limits(jog, trace: Trace) -> None:
    dq = trace.dq
    assert np.all(np.abs(dq) <= jog.limiter.max_velocity[jog._to_user] * (1 + 1e-9))
    step = np.abs(np.diff(np.vstack([np.zeros(jog.nv), dq]), axis=0))
    assert np.all(step <= jog.limiter.max_acceleration[jog._to_user] * jog.settings.pub_period * (1 + 1e-9))


def twist_moving_joint(jog, q: tuple[float, ...], joint: int, speed: float) -> tuple[float, ...]:
    """Base-frame twist that the given joint alone would produce at `q` (a way to aim at a pose)."""
    dq = np.zeros(jog.nv)
    dq[joint] = speed
    return tuple(jog.model.jacobian(np.array(q, dtype=float)) @ dq)


def toward_singularity(jog, robot: Robot) -> tuple[float, ...]:
    sign = math.copysign(1.0, robot.singular_value - robot.near_singular[robot.singular_joint])
    return twist_moving_joint(jog, robot.near_singular, robot.singular_joint, 0.3 * sign)


def test_speed_falls_smoothly_to_zero_near_singularity_and_backing_out_works(robot: Robot) -> None:
    jog = make_jog(robot)  # thresholds 7 / 12
    arm = PerfectArm(jog, robot.near_singular)
    twist = toward_singularity(jog, robot)
    trace = arm.run(400, twist)

    condition = np.array(trace.condition)
    speed = np.abs(trace.dq).max(axis=1)
    assert condition[0] > 7.0  # started inside the slow-down zone
    assert condition.max() < 12.0  # never reached the hard stop
    assert set(trace.status) == {StatusCode.DECELERATE_FOR_SINGULARITY}
    peak = int(np.argmax(speed))
    assert np.all(np.diff(speed[peak:]) <= 1e-12)  # after the start-up ramp, only slower
    assert np.all(np.diff(trace.scale) <= 1e-12)
    assert speed[-1] < 0.02 * speed[peak]
    assert_within_joint_limits(jog, trace)

    p0 = arm.eef()
    back = arm.run(100, tuple(-v for v in twist))
    assert np.linalg.norm(arm.eef() - p0) > 0.02  # moves out at full speed
    assert back.condition[-1] < condition[-1] - 3.0
    assert set(back.status) == {StatusCode.NO_WARNING}


def test_halts_at_hard_stop_but_can_back_out(robot: Robot) -> None:
    jog = make_jog(robot, singularity_threshold=5.0, hard_stop_singularity_threshold=7.0)
    arm = PerfectArm(jog, robot.near_singular)  # condition number above 7
    twist = toward_singularity(jog, robot)
    trace = arm.run(30, twist)
    assert set(trace.status) == {StatusCode.HALT_FOR_SINGULARITY}
    assert np.all(trace.dq == 0.0)
    np.testing.assert_array_equal(arm.q, robot.near_singular)

    back = arm.run(50, tuple(-v for v in twist))
    assert np.max(np.abs(arm.q - np.array(robot.near_singular))) > 0.05
    assert back.condition[-1] < back.condition[0]


@pytest.mark.parametrize("speed", [0.5, 2.5], ids=["slow", "full_speed"])
def test_joint_limit_keeps_margin_and_allows_moving_away(robot: Robot, speed: float) -> None:
    last = len(robot.start) - 1
    name = f"{make_jog(robot).joint_names[last]}"
    upper = robot.start[last] + 1.0
    jog = make_jog(robot, joint_limits={name: {"max_position": upper}}, joint_limit_margin=0.1)
    arm = PerfectArm(jog, robot.start)
    twist = twist_moving_joint(jog, robot.start, last, speed)
    trace = arm.run(300, twist)

    stop = upper - 0.1
    assert np.max(trace.q[:, last]) <= stop + 1e-12  # the margin is kept
    assert stop - trace.q[-1, last] < 1e-3  # and the arm got there
    assert StatusCode.DECELERATE_FOR_JOINT_LIMIT in trace.status
    assert trace.status[-1] == StatusCode.HALT_FOR_JOINT_LIMIT
    assert np.max(np.abs(trace.dq[-1])) == 0.0
    assert_within_joint_limits(jog, trace)

    back = arm.run(100, tuple(-v for v in twist))
    assert trace.q[-1, last] - arm.q[last] > 0.1
    assert back.status[-1] == StatusCode.NO_WARNING


def test_stale_command_decelerates_to_zero_then_stops_publishing(robot: Robot) -> None:
    jog = make_jog(robot, incoming_cmd_timeout=0.2, num_outgoing_halt_msgs_to_publish=10)
    arm = PerfectArm(jog, robot.start)
    moving = arm.run(100, (0.1, 0.0, 0.0, 0.0, 0.0, 0.3))
    after = arm.run(150)  # the sender went quiet

    stale = np.array(after.status) == StatusCode.STALE_COMMAND
    assert not stale[:19].any() and stale[21:].all()  # 0.2 s timeout at 100 Hz
    speeds = np.linalg.norm(after.dq, axis=1)
    assert np.all(np.diff(speeds[20:]) <= 1e-12)  # never speeds up again
    decel = after.dq[20:][speeds[20:] > 0.0]
    assert len(decel) >= 2  # a ramp within the acceleration limits, not a jump to zero
    cruise = decel[0]
    cosines = decel @ cruise / (np.linalg.norm(decel, axis=1) * np.linalg.norm(cruise))
    assert np.all(cosines > 0.9999)  # direction kept while slowing
    assert_within_joint_limits(jog, Trace(velocities=[*moving.velocities, *after.velocities]))

    zero_messages = [p and s == 0.0 for p, s in zip(after.publish, speeds, strict=True)]
    assert sum(zero_messages) == 10  # the final zero, repeated, then silence
    last_published = int(np.flatnonzero(after.publish)[-1])
    assert not any(after.publish[last_published + 1 :])

    restart = arm.run(5, (0.1, 0.0, 0.0, 0.0, 0.0, 0.0))
    assert all(restart.publish) and np.linalg.norm(restart.dq[-1]) > 0.0


def test_zero_command_halts_like_a_stale_one(robot: Robot) -> None:
    jog = make_jog(robot, num_outgoing_halt_msgs_to_publish=3)
    arm = PerfectArm(jog, robot.start)
    arm.run(50, (0.05, 0.0, 0.0, 0.0, 0.0, 0.0))
    trace = arm.run(100, (0.0,) * 6)
    assert not trace.publish[-1]
    assert sum(p and not v.any() for p, v in zip(trace.publish, trace.velocities, strict=True)) == 3


@pytest.mark.parametrize(
    ("twist", "frame", "reason"),
    [
        ((math.nan, 0.0, 0.0, 0.0, 0.0, 0.0), "", "non-finite"),
        ((0.0, 0.0, 0.0, 0.0, math.inf, 0.0), "", "non-finite"),
        ((0.05, 0.0, 0.0, 0.0, 0.0, 0.0), "no_such_frame", "unknown frame"),
        ((0.05, 0.0, 0.0), "", "6 components"),
    ],
    ids=["nan", "inf", "unknown_frame", "short"],
)
def test_invalid_command_rejected_and_arm_holds_still(
    robot: Robot, twist: tuple[float, ...], frame: str, reason: str
) -> None:
    jog = make_jog(robot)
    arm = PerfectArm(jog, robot.start)
    result = jog.set_command(twist, frame, 0.0)
    assert not result.accepted and reason in result.reason
    trace = arm.run(20)
    assert set(trace.status) == {StatusCode.INVALID_COMMAND}
    assert reason in trace.messages[-1]
    assert not any(trace.publish)
    np.testing.assert_array_equal(arm.q, robot.start)

    # Still works afterwards.
    arm.run(20, (0.05, 0.0, 0.0, 0.0, 0.0, 0.0))
    assert np.max(np.abs(arm.q - np.array(robot.start))) > 0.0


def test_invalid_command_while_moving_stops_smoothly(robot: Robot) -> None:
    jog = make_jog(robot)
    arm = PerfectArm(jog, robot.start)
    moving = arm.run(50, (0.05, 0.0, 0.0, 0.0, 0.0, 0.0))
    assert not jog.set_command((math.nan,) * 6, "", arm.t).accepted
    trace = arm.run(60)
    assert set(trace.status) == {StatusCode.INVALID_COMMAND}
    assert not trace.dq[-1].any()
    assert_within_joint_limits(jog, Trace(velocities=[*moving.velocities, *trace.velocities]))


def test_pause_stops_and_ignores_commands_until_resume(robot: Robot) -> None:
    jog = make_jog(robot)
    arm = PerfectArm(jog, robot.start)
    arm.run(50, (0.05, 0.0, 0.0, 0.0, 0.0, 0.0))
    jog.pause()
    trace = arm.run(100, (0.05, 0.0, 0.0, 0.0, 0.0, 0.0))
    assert set(trace.status) == {StatusCode.PAUSED}
    assert not jog.set_command((0.05, 0, 0, 0, 0, 0), "", arm.t).accepted
    held = arm.q.copy()
    arm.run(10)
    np.testing.assert_array_equal(arm.q, held)
    jog.resume()
    assert arm.run(1).status[-1] == StatusCode.STALE_COMMAND  # the old command does not come back
    resumed = arm.run(20, (0.05, 0.0, 0.0, 0.0, 0.0, 0.0))
    assert resumed.status[-1] == StatusCode.NO_WARNING
    assert np.max(np.abs(arm.q - held)) > 0.0


def test_no_joint_state_means_no_output(robot: Robot) -> None:
    jog = make_jog(robot)
    jog.set_command((0.05, 0.0, 0.0, 0.0, 0.0, 0.0), "", 0.0)
    out = jog.step(0.0)
    assert not out.publish and out.status == StatusCode.NO_JOINT_STATE


def test_bad_joint_states_are_refused_and_keep_the_last_good_one(robot: Robot) -> None:
    jog = make_jog(robot)
    names = list(jog.joint_names)
    jog.set_joint_state(robot.start)
    with pytest.raises(ValueError, match="finite"):
        jog.set_joint_state([math.nan] * len(names))
    assert not jog.set_joint_state_named(names[:-1], robot.start[:-1])  # a joint missing
    assert not jog.set_joint_state_named(names, [math.inf] * len(names))
    assert jog.set_joint_state_named(["gripper", *names[::-1]], [0.3, *robot.start[::-1]])  # extra, reordered
    jog.set_command((0.0,) * 6, "", 0.0)
    out = jog.step(0.0)
    np.testing.assert_array_equal(out.positions, robot.start)


def test_resyncs_to_measured_state_when_tracking_error_is_large(robot: Robot) -> None:
    jog = make_jog(robot, max_tracking_error=0.1)
    arm = PerfectArm(jog, robot.start)
    arm.run(20, (0.05, 0.0, 0.0, 0.0, 0.0, 0.0))
    pushed = arm.q.copy()
    pushed[0] += 0.3  # the robot was pushed away from where it was told to be
    jog.set_joint_state(pushed)
    jog.set_command((0.05, 0.0, 0.0, 0.0, 0.0, 0.0), "", arm.t)
    out = jog.step(arm.t)
    assert "re-synced" in out.message
    assert abs(out.positions[0] - pushed[0]) < 0.01
