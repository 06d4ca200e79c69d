"""Continuous joints: jog_arm follows twists through +-pi, skips their position limits, keeps speed limits.

The test arm (written here) has a Kinova-like layout: base yaw, forearm roll and tool roll are continuous
(the URDF's lower/upper on them, which URDF says to ignore, are set to +-6.28 on purpose), shoulder, elbow
and wrist pitch are revolute. The real Jaco2 from example-robot-data is checked at the end.
"""

from __future__ import annotations

import math

import numpy as np
import pinocchio as pin
import pytest
from jog_arm.limits import JointLimiter
from jog_arm_testing import ROBOTS_DIR, PerfectArm, angle_deg

from jog_arm import ArmModel, JogCalcs, JogSettings, KinematicsError, StatusCode

# name, type, axis, origin in the parent link (x y z), velocity limit [rad/s]
_JOINTS = [
    ("yaw", "continuous", "0 0 1", "0 0 0.1", 1.5),
    ("shoulder", "revolute", "0 1 0", "0 0 0.1", 1.5),
    ("elbow", "revolute", "0 1 0", "0 0 0.4", 1.5),
    ("forearm_roll", "continuous", "1 0 0", "0.35 0 0", 2.0),
    ("wrist_pitch", "revolute", "0 1 0", "0.05 0 0", 2.0),
    ("tool_roll", "continuous", "1 0 0", "0.05 0 0", 1.0),
]
NAMES = [j[0] for j in _JOINTS]
CONTINUOUS = [i for i, j in enumerate(_JOINTS) if j[1] == "continuous"]
TOOL_ROLL = NAMES.index("tool_roll")
YAW = NAMES.index("yaw")
# Elbow and wrist bent: condition number ~3.7, far from every revolute limit.
START = (0.0, 0.0, 0.6, 0.0, 1.5, 0.0)


def arm_urdf(no_velocity: str = "", how: str = "no limit") -> str:
    """The 6-joint test arm; joint `no_velocity` gets no <limit> ("no limit") or velocity="0" ("zero")."""
    parts = ['<robot name="turner">', '<link name="base"/>']
    parent = "base"
    for i, (name, jtype, axis, xyz, velocity) in enumerate(_JOINTS):
        child = f"link{i + 1}"
        bounds = 'lower="-6.28" upper="6.28"' if jtype == "continuous" else 'lower="-2.8" upper="2.8"'
        limit = f'<limit effort="10" {bounds} velocity="{velocity}"/>'
        if name == no_velocity:
            limit = "" if how == "no limit" else f'<limit effort="10" {bounds} velocity="0"/>'
        parts += [
            f'<link name="{child}"/>',
            f'<joint name="{name}" type="{jtype}"><parent link="{parent}"/><child link="{child}"/>'
            f'<origin xyz="{xyz}" rpy="0 0 0"/><axis xyz="{axis}"/>{limit}</joint>',
        ]
        parent = child
    parts += [
        '<link name="tip"/>',
        f'<joint name="tip_joint" type="fixed"><parent link="{parent}"/><child link="tip"/>'
        '<origin xyz="0.1 0 0" rpy="0 0 0"/></joint>',
        "</robot>",
    ]
    return "".join(parts)


def make_jog(**params: object) -> JogCalcs:
    merged = {
        "ee_frame_name": "tip",
        "planning_frame": "base",
        "command_in_type": "speed_units",
        "pub_period": 0.01,
        "incoming_cmd_timeout": 0.5,
        **params,
    }
    return JogCalcs(JogSettings.from_params(merged), arm_urdf())


def _start(**angles: float) -> tuple[float, ...]:
    q = list(START)
    for name, value in angles.items():
        q[NAMES.index(name)] = value
    return tuple(q)


def test_continuous_joints_are_unbounded_with_speed_limits() -> None:
    jog = make_jog()
    model = jog.model
    assert model.joint_names == tuple(NAMES)
    assert [i for i, c in enumerate(model.continuous) if c] == CONTINUOUS
    for i in CONTINUOUS:
        # Neither the URDF's +-6.28 nor Pinocchio's +-1.01 on (cos, sin).
        assert model.lower[i] == -math.inf and model.upper[i] == math.inf
    np.testing.assert_allclose(model.max_velocity, [j[4] for j in _JOINTS])
    assert model.model.nq == 9 and model.nv == 6  # (cos, sin) inside, one angle per joint outside


def test_rotation_about_the_tool_axis_turns_the_tool_roll_past_pi() -> None:
    jog = make_jog()
    arm = PerfectArm(jog, _start(tool_roll=2.9))
    tip0, rot0 = arm.eef(), arm.eef_rotation()
    trace = arm.run(100, (0.0, 0.0, 0.0, 0.8, 0.0, 0.0), frame="tip")  # 0.8 rad/s about the tool's x axis
    q = trace.q
    assert q[-1, TOOL_ROLL] > math.pi + 0.4, "the tool roll must keep turning past pi"
    assert np.all(np.diff(q[:, TOOL_ROLL]) >= 0.0), "no jump back by a turn at pi"
    others = [i for i in range(6) if i != TOOL_ROLL]
    np.testing.assert_allclose(q[-1, others], np.array(START)[others], atol=1e-6)
    turned = q[-1, TOOL_ROLL] - 2.9
    expected = rot0 @ pin.exp3(np.array([turned, 0.0, 0.0]))
    np.testing.assert_allclose(arm.eef_rotation(), expected, atol=1e-9)
    np.testing.assert_allclose(arm.eef(), tip0, atol=1e-9)
    assert StatusCode.DECELERATE_FOR_JOINT_LIMIT not in trace.status
    assert StatusCode.HALT_FOR_JOINT_LIMIT not in trace.status


@pytest.mark.parametrize("start_yaw", [3.0, -3.0, 6.1])
def test_linear_twist_carries_the_base_yaw_through_pi(start_yaw: float) -> None:
    jog = make_jog()
    arm = PerfectArm(jog, _start(yaw=start_yaw))
    tip0 = arm.eef()
    radial = tip0[:2] / np.linalg.norm(tip0[:2])
    tangent = np.array([-radial[1], radial[0], 0.0]) * math.copysign(1.0, start_yaw)  # yaw grows away from 0
    twist = (*(0.1 * tangent), 0.0, 0.0, 0.0)
    trace = arm.run(150, twist)
    yaw = trace.q[:, YAW]
    if start_yaw < 0:
        assert yaw[-1] < -math.pi, "the base yaw must turn past -pi"
    else:
        assert yaw[-1] > math.ceil(start_yaw / math.pi) * math.pi, "the base yaw must turn past the next pi"
    for k in range(10, 150, 10):  # every 0.1 s the tip moves along the commanded direction
        step = trace.positions[k], trace.positions[k - 10]
        moved = jog.eef_pose(step[0]).translation - jog.eef_pose(step[1]).translation
        assert angle_deg(moved, np.array(twist[:3])) < 1.0
    assert StatusCode.DECELERATE_FOR_JOINT_LIMIT not in trace.status


def test_velocity_limit_of_a_continuous_joint_scales_the_command() -> None:
    jog = make_jog()
    arm = PerfectArm(jog, START)
    trace = arm.run(100, (0.0, 0.0, 0.0, 3.0, 0.0, 0.0), frame="tip")  # 3 rad/s: the tool roll allows 1
    assert trace.status[-1] == StatusCode.JOINT_VELOCITY_SCALED
    assert abs(trace.dq[-1, TOOL_ROLL]) == pytest.approx(1.0, rel=1e-3)
    assert np.max(np.abs(trace.dq[:, TOOL_ROLL])) <= 1.0 + 1e-9


def test_limiter_skips_joints_without_stops() -> None:
    inf = math.inf
    limiter = JointLimiter([-1.0, -inf], [1.0, inf], [1.0, 1.0], [3.0, 3.0], 0.1, 0.2, 0.01)
    # Joint 1 is at 100 rad, joint 0 is free: nothing to limit, however far joint 1 has turned.
    assert limiter.position_scale([0.0, 100.0], [0.0, 1.0]) == 1.0
    assert limiter.step_scale([0.0, -100.0], [0.0, -1.0]) == 1.0
    assert limiter.within_stops([0.0, 1e6])
    # Joint 0 at its stop still halts the whole vector.
    assert limiter.position_scale([0.9, 100.0], [0.5, 1.0]) == 0.0
    assert limiter.velocity_scale([0.0, 2.0]) == 0.5


@pytest.mark.parametrize("how", ["no limit", "zero"])
def test_continuous_joint_without_velocity_limit_needs_one_in_the_yaml(how: str) -> None:
    settings = JogSettings.from_params({"ee_frame_name": "tip", "planning_frame": "base"})
    with pytest.raises(KinematicsError, match="joint_limits/tool_roll/max_velocity"):
        JogCalcs(settings, arm_urdf("tool_roll", how))
    fixed = JogSettings.from_params({
        "ee_frame_name": "tip",
        "planning_frame": "base",
        "joint_limits": {"tool_roll": {"max_velocity": 0.7}},
    })
    jog = JogCalcs(fixed, arm_urdf("tool_roll", how))
    assert jog.model.max_velocity[TOOL_ROLL] == 0.7


def test_a_driver_that_wraps_the_angle_causes_no_resync() -> None:
    jog = make_jog()
    arm = PerfectArm(jog, _start(tool_roll=3.0))
    period = jog.settings.pub_period
    positions = []
    for _ in range(60):
        jog.set_command((0.0, 0.0, 0.0, 0.8, 0.0, 0.0), "tip", arm.t)
        out = jog.step(arm.t)
        assert "re-synced" not in out.message
        positions.append(out.positions[TOOL_ROLL])
        wrapped = list(out.positions)
        wrapped[TOOL_ROLL] = math.remainder(wrapped[TOOL_ROLL], math.tau)  # the driver reports (-pi, pi]
        jog.set_joint_state(wrapped)
        arm.t += period
    assert positions[-1] > math.pi + 0.2
    assert np.all(np.diff(positions) > 0.0), "the command goes on unwrapped, without a turn's jump"


# --- the Kinova Jaco2 of example-robot-data ------------------------------------------------------------

KINOVA_URDF = ROBOTS_DIR / "kinova_description/robots/kinova.urdf"
KINOVA_TIP = "j2s6s200_end_effector"  # the URDF's end-effector link, fixed 0.16 m beyond joint 6
# Kinova's "home" posture (joints 1, 4, 6 continuous, past pi here on purpose).
KINOVA_HOME = (4.80, 2.92, 1.00, 4.19, 1.44, 1.31)


def _fk(model: ArmModel, q: np.ndarray) -> pin.SE3:
    return model.frame_pose(q, KINOVA_TIP)


def test_kinova_loads_and_its_jacobian_matches_finite_differences() -> None:
    model = ArmModel(KINOVA_URDF.read_text(), KINOVA_TIP)
    assert model.joint_names == tuple(f"j2s6s200_joint_{i}" for i in range(1, 7))
    assert model.continuous == (True, False, False, True, False, True)
    for q in (np.array(KINOVA_HOME), np.array([-2.5, 3.5, 2.0, 7.0, 3.0, -4.0])):
        J = model.jacobian(q).copy()
        h = 1e-6
        numeric = np.zeros((6, 6))
        for i in range(6):
            plus, minus = q.copy(), q.copy()
            plus[i] += h
            minus[i] -= h
            a, b = _fk(model, plus), _fk(model, minus)
            numeric[:3, i] = (a.translation - b.translation) / (2 * h)
            numeric[3:, i] = pin.log3(a.rotation @ b.rotation.T) / (2 * h)  # angular velocity, root axes
        np.testing.assert_allclose(J, numeric, atol=1e-6)
        # An angle and the same angle a turn later are the same posture for the continuous joints.
        turned = q.copy()
        turned[[0, 3, 5]] += 2 * math.pi
        assert _fk(model, turned).isApprox(_fk(model, q), 1e-9)


def test_kinova_jogs_from_its_home_posture() -> None:
    settings = JogSettings.from_params({
        "ee_frame_name": KINOVA_TIP,
        "planning_frame": "base",
        "command_in_type": "speed_units",
        "pub_period": 0.01,
    })
    jog = JogCalcs(settings, KINOVA_URDF.read_text())
    arm = PerfectArm(jog, KINOVA_HOME)
    start = arm.eef()
    trace = arm.run(50, (0.0, 0.05, 0.0, 0.0, 0.0, 0.0))
    moved = arm.eef() - start
    assert trace.status[-1] == StatusCode.NO_WARNING
    assert angle_deg(moved, np.array([0.0, 1.0, 0.0])) < 1.0
    assert np.linalg.norm(moved) == pytest.approx(0.05 * 0.5, rel=0.1)
