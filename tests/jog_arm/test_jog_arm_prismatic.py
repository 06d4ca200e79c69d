"""A linear axis under the arm (tests/data/rail_arm.urdf: UR5 kinematics on a rail along x): the rail is a
joint in metres, with its own limit margin and slow-down zone (jog_arm README, step 6)."""

from __future__ import annotations

import pathlib

import numpy as np
import pytest
from jog_arm.settings import SettingsError
from jog_arm_testing import PerfectArm, Robot, make_jog

RAIL = Robot(
    "rail_arm",
    pathlib.Path(__file__).resolve().parents[1] / "data" / "rail_arm.urdf",
    "tool0",
    "rail",
    # The rail 0.04 m from its +0.45 m limit; the arm as make robot's start pose (tool down).
    (0.41, -0.0012, -0.1381, -0.537, -0.8958, -1.5708, -0.0012),
    (),
    0,
    0.0,
)


def test_the_rail_is_a_linear_joint_and_keeps_its_margin_in_metres() -> None:
    jog = make_jog(RAIL)
    assert jog.model.prismatic == (True, False, False, False, False, False, False)
    arm = PerfectArm(jog, RAIL.start)
    x0 = arm.eef()[0]
    trace = arm.run(600, (0.1, 0.0, 0.0, 0.0, 0.0, 0.0))  # 6 s toward +x, the rail's own direction
    rail = trace.q[:, 0]
    # It runs on toward its limit and stops 0.01 m (prismatic_limit_margin) short of it, not at the
    # revolute joints' 0.1 (which the rail was already inside: it would not have moved).
    assert rail.max() <= 0.45 - 0.01 + 1e-9
    assert rail[-1] > 0.43
    assert arm.eef()[0] - x0 > 0.02
    assert np.all(np.abs(trace.velocities[-1]) < 1e-9)  # stopped at the stop, not pushing through it


@pytest.mark.parametrize("width", [0.1, 0.2])  # wide enough that the ramp binds, not the braking
def test_the_rails_slow_down_zone_is_its_own(width: float) -> None:
    jog = make_jog(RAIL, prismatic_slowdown_width=width)
    lim = jog.limiter
    rail_speed = jog.model.max_velocity[0]  # 1 m/s (the URDF)
    # 0.03 m before the stop (0.44 m), the ramp allows rail_speed x 0.03 / width toward it.
    dq = np.zeros(7)
    dq[0] = rail_speed
    assert lim.position_scale([0.41, *RAIL.start[1:]], dq.tolist()) == pytest.approx(
        0.03 / width, rel=0.01)


# The rail 0.3 m off its middle, the arm folded (its tool 0.61 m from the carriage along x, so the arm can
# reach over the rail's middle: at the stretched RAIL.start, 0.82 m out, it cannot, and the rail's share of
# the self-motion is 0.009).
FOLDED = (0.3, 0.0, -1.2, 1.6, -1.97, -1.571, 0.0)


def test_a_free_rail_pulled_alone_goes_toward_its_middle_while_the_tool_goes_where_it_is_told() -> None:
    """`nullspace_joints: [rail_joint]` with the rail's middle (0) in the posture: jogging the tool 0.1 m
    along y and back, the self-motion takes the rail from 0.3 m to under 0.1 m, and the tool keeps its line;
    pulling every joint toward the same posture (the default), the projected pull leaves the rail out (its
    share of the self-motion is small)."""
    ends = {}
    for joints in ((), ("rail_joint",)):
        jog = make_jog(RAIL, nullspace_gain=1.0, nullspace_joints=list(joints),
                       nullspace_posture=[0.0, *FOLDED[1:]])
        arm = PerfectArm(jog, FOLDED)
        p0 = arm.eef()
        off = []
        for vy in (0.05, -0.05):
            for _ in range(200):
                arm.run(1, (0.0, vy, 0.0, 0.0, 0.0, 0.0))
                d = arm.eef() - p0
                off.append(float(np.hypot(d[0], d[2])))
        assert max(off) < 3e-3, (joints, max(off))  # on the commanded line
        assert abs(arm.eef()[1] - p0[1]) < 4e-3  # and back
        ends[joints] = arm.q[0]
    assert ends[("rail_joint",)] < 0.1, ends
    assert ends[()] > 0.25, ends


def test_a_pulled_joint_that_is_not_controlled_is_refused_by_name() -> None:
    with pytest.raises(SettingsError, match="nullspace_joints: \\['elbow'\\]"):
        make_jog(RAIL, nullspace_joints=["elbow"])
