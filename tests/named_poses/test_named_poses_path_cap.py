"""The collaborative speed cap on named-pose moves: the tip never goes faster than jog_arm's cap for the
direction it moves in, the cap binds (the move is not slower than it needs to be), and off means off."""

from __future__ import annotations

import math
import pathlib
import sys

import numpy as np
import pytest
from jog_arm.body_regions import REGIONS, max_speed
from jog_arm.kinematics import ArmModel
from jog_arm.speed_cap import SpeedCap
from named_poses.path_cap import PathCap
from named_poses.profile import plan_move

pytestmark = pytest.mark.cobot_safety

URDF = (pathlib.Path(sys.prefix) / "lib/python3.11/site-packages/cmeel.prefix/share/example-robot-data/robots"
        / "ur_description/urdf/ur5_robot.urdf").read_text()
JOINTS = ["shoulder_pan_joint", "shoulder_lift_joint", "elbow_joint", "wrist_1_joint", "wrist_2_joint",
          "wrist_3_joint"]
START = np.array([0.0, -1.2, 1.5, -1.9, -1.57, 0.3])
GOAL = START + np.array([1.5, 0.3, -0.3, 0.0, 0.0, 0.0])  # a wide swing of the shoulder
LIMITS = ([2.0] * 6, [4.0] * 6)  # [rad/s, rad/s^2]: fast enough for the tip to exceed the face's cap


def _tip_speeds_and_caps(move, region: str) -> tuple[np.ndarray, np.ndarray]:
    """Per sample interval: the tip's speed (finite differences of the forward kinematics) and the cap for
    the direction it moves in at the interval's middle (jog_arm's SpeedCap, checked against CRBA there)."""
    model = ArmModel(URDF, "tool0", JOINTS)
    cap = SpeedCap(model, 1.0, region, 0.0)
    tips = np.array([model.frame_pose(q, "tool0").translation for q in move.positions])
    speeds, caps = [], []
    for k in range(1, len(tips)):
        step = tips[k] - tips[k - 1]
        if not np.any(step):
            continue
        middle = 0.5 * (move.positions[k] + move.positions[k - 1])
        mass = cap.robot_mass(middle.tolist(), model.jacobian(middle), step)
        speeds.append(np.linalg.norm(step) / (move.times[k] - move.times[k - 1]))
        caps.append(max_speed(REGIONS[region], mass))
    return np.array(speeds), np.array(caps)


def test_a_move_toward_the_face_is_capped_at_the_tip_and_the_cap_binds():
    reading = PathCap(URDF, JOINTS, "tool0").limit("face", 0.0, START, GOAL)
    free = plan_move(START, GOAL, *LIMITS)
    capped = plan_move(START, GOAL, *LIMITS, max_path_speed=reading.speed)
    speeds, caps = _tip_speeds_and_caps(free, "face")
    assert np.max(speeds / caps) > 1.5  # without the cap the tip would be too fast for a face
    speeds, caps = _tip_speeds_and_caps(capped, "face")
    ratio = speeds / caps
    print(f"\nface: free {free.duration:.2f} s, capped {capped.duration:.2f} s, tip speed / cap max "
          f"{ratio.max():.3f}, peak tip speed {speeds.max():.3f} m/s")
    assert ratio.max() <= 1.01 and ratio.max() > 0.95
    assert capped.duration > free.duration


def test_off_leaves_the_move_alone_and_an_unknown_region_is_refused():
    path_cap = PathCap(URDF, JOINTS, "tool0")
    assert path_cap.limit("off", 0.0, START, GOAL).speed == math.inf
    assert path_cap.limit("hand", 0.0, START, START).speed == math.inf  # nothing moves
    with pytest.raises(ValueError, match="unknown body region"):
        path_cap.limit("elbows", 0.0, START, GOAL)


def test_the_poses_joint_order_is_mapped_to_the_model():
    reordered = [JOINTS[i] for i in (5, 4, 3, 2, 1, 0)]
    forward = PathCap(URDF, JOINTS, "tool0").limit("chest", 0.0, START, GOAL)
    backward = PathCap(URDF, reordered, "tool0").limit("chest", 0.0, START[::-1], GOAL[::-1])
    assert backward.speed == pytest.approx(forward.speed, rel=1e-9)
