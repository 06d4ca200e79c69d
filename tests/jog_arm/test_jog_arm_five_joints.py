"""An arm with fewer than six joints (the SO-100, 5): translation first, rotation as far as the arm can,
and the rotation it cannot make named (jog_arm README, *Fewer than six joints*)."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest
from jog_arm_testing import SO100, UR5, PerfectArm, angle_deg, make_jog

from jog_arm import StatusCode

SPEED = 0.02  # [m/s]


@pytest.mark.parametrize("direction", [(1, 0, 0), (0, 1, 0), (0, 0, 1), (-1, 1, 0)],
                         ids=["x", "y", "z", "-xy"])
def test_a_translation_is_followed_whatever_the_rotation_asked(direction: tuple[int, ...]) -> None:
    """A twist with a rotation the arm cannot make alongside: the tip still moves along the translation
    (translation first); the rotation is what is left."""
    jog = make_jog(SO100)
    arm = PerfectArm(jog, SO100.start)
    arm.run(1)
    axis = np.array(jog.uncontrolled_rotations()[0])
    unit = np.array(direction, dtype=float) / np.linalg.norm(direction)
    p0 = arm.eef()
    trace = arm.run(50, (*(SPEED * unit), *(0.2 * axis)))
    moved = arm.eef() - p0
    assert np.linalg.norm(moved) > 0.5 * SPEED * 0.5
    assert angle_deg(moved, unit) < 1.0
    assert StatusCode.HALT_FOR_SINGULARITY not in trace.status


def test_a_rotation_the_arm_can_make_keeps_the_tip_in_place() -> None:
    jog = make_jog(SO100)
    arm = PerfectArm(jog, SO100.start)
    arm.run(1)
    (uncontrolled,) = jog.uncontrolled_rotations()
    axis = np.cross(uncontrolled, (0.0, 0.0, 1.0))
    axis /= np.linalg.norm(axis)
    p0, r0 = arm.eef(), arm.eef_rotation()
    arm.run(50, (0.0, 0.0, 0.0, *(0.3 * axis)))
    turned = pin.log3(arm.eef_rotation() @ r0.T)
    assert np.linalg.norm(turned) > 0.1
    assert angle_deg(turned, axis) < 10.0  # the free axis turns with the arm: not exactly the asked one
    assert np.linalg.norm(arm.eef() - p0) < 5e-4


def test_the_rotation_it_cannot_make_is_named_and_not_made() -> None:
    """One axis for five joints, a unit vector; asked to turn about it alone, the arm stays where it is."""
    jog = make_jog(SO100)
    arm = PerfectArm(jog, SO100.start)
    arm.run(1)
    axes = jog.uncontrolled_rotations()
    assert len(axes) == 1 and np.linalg.norm(axes[0]) == pytest.approx(1.0)
    p0, r0 = arm.eef(), arm.eef_rotation()
    arm.run(20, (0.0, 0.0, 0.0, *(0.3 * np.array(axes[0]))))
    assert np.linalg.norm(arm.eef() - p0) < 1e-4
    assert np.linalg.norm(pin.log3(arm.eef_rotation() @ r0.T)) < 0.003  # 0.06 rad asked


def test_six_joints_have_no_uncontrolled_rotation() -> None:
    jog = make_jog(UR5)
    jog.set_joint_state(UR5.start)
    assert jog.uncontrolled_rotations() == []
