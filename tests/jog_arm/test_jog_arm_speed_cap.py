"""The collaborative speed cap (ISO/TS 15066): the formula against numbers worked by hand, the arm's
effective mass against a two-link arm worked by hand and against Pinocchio's CRBA on the UR5 and the Panda,
and jog_arm slowing a fast jog to the cap, saying so, and leaving slower jogs alone."""

from __future__ import annotations

import math

import numpy as np
import pinocchio as pin
import pytest
from jog_arm.body_regions import REGIONS, max_speed, region_named
from jog_arm.kinematics import ArmModel
from jog_arm.speed_cap import SpeedCap
from jog_arm.status import StatusCode
from jog_arm_testing import PANDA, UR5, PerfectArm, Robot, make_jog

pytestmark = pytest.mark.cobot_safety

# Worked by hand: hand (Annex A: 140 N quasi-static, F_T = 280 N, k = 75 N/mm, m_H = 0.6 kg), m_R = 10 kg:
# mu = 1 / (1/0.6 + 1/10) = 0.5660 kg, v = 280 / sqrt(0.5660 * 75000) = 1.359 m/s. Face (65 N, no transient
# contact: F_T = 65 N, 75 N/mm, 4.4 kg), m_R = 10 kg: mu = 3.0556 kg, v = 65 / sqrt(3.0556 * 75000) = 0.1358.
# Chest (F_T 280 N, 25 N/mm, 40 kg), m_R = 10 kg: mu = 8 kg, v = 280 / sqrt(8 * 25000) = 0.6261 m/s.
HAND_10KG, FACE_10KG, CHEST_10KG = 1.359, 0.1358, 0.6261


def test_max_speed_matches_the_worked_numbers():
    assert max_speed(REGIONS["hand"], 10.0) == pytest.approx(HAND_10KG, rel=1e-3)
    assert max_speed(REGIONS["face"], 10.0) == pytest.approx(FACE_10KG, rel=1e-3)
    assert max_speed(REGIONS["chest"], 10.0) == pytest.approx(CHEST_10KG, rel=1e-3)
    assert max_speed(REGIONS["hand"], 0.0) == math.inf  # nothing moves that way
    assert max_speed(REGIONS["hand"], 1.0) > max_speed(REGIONS["hand"], 50.0)  # heavier: slower


def test_an_unknown_region_is_refused_with_the_known_ones():
    with pytest.raises(ValueError, match=r"unknown body region 'hands'.*hand"):
        region_named("hands")


TWO_LINK = """<robot name="two_link">
  <link name="base"/>
  <link name="link1"><inertial><origin xyz="0.4 0 0"/><mass value="3.0"/>
    <inertia ixx="1e-9" iyy="1e-9" izz="1e-9" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="link2"><inertial><origin xyz="0.3 0 0"/><mass value="2.0"/>
    <inertia ixx="1e-9" iyy="1e-9" izz="1e-9" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="tip"/>
  <joint name="j1" type="revolute"><parent link="base"/><child link="link1"/><axis xyz="0 0 1"/>
    <limit lower="-3" upper="3" effort="10" velocity="1"/></joint>
  <joint name="j2" type="revolute"><parent link="link1"/><child link="link2"/><origin xyz="0.4 0 0"/>
    <axis xyz="0 0 1"/><limit lower="-3" upper="3" effort="10" velocity="1"/></joint>
  <joint name="tip_joint" type="fixed"><parent link="link2"/><child link="tip"/><origin xyz="0.3 0 0"/>
  </joint>
</robot>"""


def test_a_two_link_arm_has_the_effective_masses_worked_by_hand():
    """Point masses m1 = 3 kg at the elbow, m2 = 2 kg at the tip, link 1 along x, the elbow at 90 deg:
    along x only the forearm turns (m = m2 = 2 kg); along y the shoulder carries both (m1 + m2 = 5 kg)."""
    model = ArmModel(TWO_LINK, "tip", (), {}, 1.0, {})
    cap = SpeedCap(model, 1.0, "hand", payload=0.5)  # length scale 1: J and twists as they are
    q = [0.0, math.pi / 2]
    J = model.jacobian(np.asarray(q))
    assert cap.robot_mass(q, J, np.array([1.0, 0.0, 0.0])) == pytest.approx(2.0 + 0.5, rel=1e-6)
    assert cap.robot_mass(q, J, np.array([0.0, -3.0, 0.0])) == pytest.approx(5.0 + 0.5, rel=1e-6)
    # hand, m_R 2.5 kg: mu = 1 / (1/0.6 + 1/2.5) = 0.4839 kg, v = 280 / sqrt(0.4839 * 75000) = 1.470 m/s
    assert cap.scale(q, J, np.array([3.0, 0.0, 0.0, 0.0, 0.0, 0.0])) == pytest.approx(1.470 / 3.0, rel=1e-3)
    assert cap.last.speed == pytest.approx(1.470, rel=1e-3)


def _reference_mass(robot: Robot, direction: np.ndarray, payload: float) -> float:
    """1 / (u^T J M^-1 J^T u) + payload from Pinocchio's CRBA and numpy's inverse, the joints off the tip's
    chain (the Panda's fingers) locked."""
    full = pin.buildModelFromUrdf(str(robot.urdf_path))
    frame = full.getFrameId(robot.tip)
    chain = set(full.supports[full.frames[frame].parentJoint])
    locked = [j for j in range(1, full.njoints) if j not in chain]
    model = pin.buildReducedModel(full, locked, pin.neutral(full)) if locked else full
    data = model.createData()
    q = np.asarray(robot.start)
    M = pin.crba(model, data, q)
    M = np.triu(M) + np.triu(M, 1).T
    J = pin.computeFrameJacobian(model, data, q, model.getFrameId(robot.tip), pin.LOCAL_WORLD_ALIGNED)[:3]
    u = direction / np.linalg.norm(direction)
    return 1.0 / float(u @ J @ np.linalg.inv(M) @ J.T @ u) + payload


@pytest.mark.parametrize("robot", [UR5, PANDA], ids=lambda r: r.name)
@pytest.mark.parametrize("direction", [(1.0, 0.0, 0.0), (0.0, 0.6, -0.8)], ids=["x", "yz"])
@pytest.mark.parametrize("region", ["hand", "chest"])
def test_the_cap_at_the_start_pose_matches_the_reference_within_one_percent(robot, direction, region):
    jog = make_jog(robot, collaborative_region=region, collaborative_payload=1.0)
    arm = PerfectArm(jog, robot.start)
    twist = (*(0.05 * np.asarray(direction)), 0.0, 0.0, 0.0)  # slow: below any cap, so nothing changes
    arm.run(1, twist)
    mass = _reference_mass(robot, np.asarray(direction), 1.0)
    expected = max_speed(REGIONS[region], mass)
    assert jog.speed_cap.last.robot_mass == pytest.approx(mass, rel=0.01)
    assert jog.speed_cap.last.speed == pytest.approx(expected, rel=0.01)
    print(f"\n{robot.name} {region} along {direction}: m_R {mass:.2f} kg, cap {expected:.3f} m/s")


def _last_speed(jog, trace) -> float:
    """The tip's speed over the last cycle [m/s]."""
    a, b = (jog.eef_pose(q).translation for q in trace.positions[-2:])
    return float(np.linalg.norm(b - a)) / jog.settings.pub_period


@pytest.mark.parametrize("robot", [UR5, PANDA], ids=lambda r: r.name)
def test_a_fast_jog_is_slowed_to_the_cap_and_says_so(robot):
    jog = make_jog(robot, pub_period=0.002, collaborative_region="face", collaborative_payload=1.0)
    arm = PerfectArm(jog, robot.start)
    p0 = arm.eef()
    trace = arm.run(400, (0.0, 0.0, -0.5, 0.0, 0.0, 0.0))  # 0.8 s at 0.5 m/s requested
    cap = jog.speed_cap.last.speed
    assert 0.05 < cap < 0.3  # the face at these masses: well below 0.5 m/s
    speed = _last_speed(jog, trace)
    assert speed == pytest.approx(cap, rel=0.02)
    assert trace.status[-1] == StatusCode.COLLABORATIVE_SPEED_CAP
    assert "face" in trace.messages[-1] and f"{cap:.3f} m/s" in trace.messages[-1]
    assert trace.scale[-1] == pytest.approx(cap / 0.5, rel=0.02)
    assert np.linalg.norm(arm.eef() - p0) < 0.5 * 0.8  # never faster than asked either
    # Live: off, and the same jog runs faster than the cap (as fast as the joints' limits let it).
    jog.retune(jog.settings.retuned({"collaborative_region": "off"}))
    trace = arm.run(100, (0.0, 0.0, -0.5, 0.0, 0.0, 0.0))
    assert _last_speed(jog, trace) > 2.0 * cap and trace.status[-1] != StatusCode.COLLABORATIVE_SPEED_CAP
    assert jog.speed_cap.last.speed == math.inf


def test_a_jog_below_the_cap_and_a_pure_rotation_are_left_alone():
    jog = make_jog(UR5, collaborative_region="hand")
    arm = PerfectArm(jog, UR5.start)
    trace = arm.run(100, (0.1, 0.0, 0.0, 0.0, 0.0, 0.0))
    assert trace.status[-1] == StatusCode.NO_WARNING and trace.scale[-1] == 1.0
    assert 1.0 < jog.speed_cap.last.speed < math.inf
    trace = arm.run(100, (0.0, 0.0, 0.0, 0.0, 0.0, 0.5))  # the tip's origin does not move
    assert trace.status[-1] == StatusCode.NO_WARNING and jog.speed_cap.last.speed == math.inf


@pytest.mark.parametrize("robot", [UR5, PANDA], ids=lambda r: r.name)
def test_the_inverse_mass_reused_within_a_hundredth_of_a_radian_moves_the_cap_under_two_tenths_percent(robot):
    jog = make_jog(robot, collaborative_region="hand")
    cap, region = jog.speed_cap, REGIONS["hand"]
    rng = np.random.default_rng(1)
    worst = 0.0
    for _ in range(300):
        q0 = np.asarray(robot.start) + rng.normal(0.0, 0.3, len(robot.start))
        q1 = q0 + rng.choice([-1.0, 1.0], len(q0)) * 0.0099  # every joint just inside the reuse distance
        u = rng.normal(size=3)
        masses = []
        for q in (q0, q1):
            cap.configure("hand", 0.0)  # forget: computed here
            g = jog.solver.geometry(q.tolist())
            masses.append(cap.robot_mass(g.q, g.J, u))
        worst = max(worst, abs(max_speed(region, masses[1]) / max_speed(region, masses[0]) - 1.0))
    assert worst < 0.002
    # And it is reused there: the mass a hundredth of a radian away is the one computed before.
    g = jog.solver.geometry(list(robot.start))
    first = cap.robot_mass(g.q, g.J, np.array([1.0, 0.0, 0.0]))
    near = jog.solver.geometry((np.asarray(robot.start) + 0.009).tolist())
    assert cap.robot_mass(near.q, near.J, np.array([1.0, 0.0, 0.0])) == first
    far = jog.solver.geometry((np.asarray(robot.start) + 0.02).tolist())
    assert cap.robot_mass(far.q, far.J, np.array([1.0, 0.0, 0.0])) != first
