"""compliant_rviz.markers (pure): what the RViz view writes and draws from the stack's state."""

from __future__ import annotations

import math
import pathlib

import numpy as np
import pinocchio as pin
import pytest
import yaml
from compliant_rviz.markers import (
    ARROW_SECONDS,
    AxisLine,
    Box,
    Trail,
    axis_text,
    cap_text,
    obstacle_box,
    velocity_arrow,
)

SRC = pathlib.Path(__file__).resolve().parents[2] / "src"


def test_the_text_names_each_axis_law_with_its_force_and_velocity_and_says_when_safety_is_not_ok():
    lines = [AxisLine("x", "none", 0.0, 0.0, "none"), AxisLine("y", "path", 0.5, 0.0, "none"),
             AxisLine("z", "force_tracking", 10.04, -0.0003),
             AxisLine("rz", "spring", -0.2, 0.0349, "max travel"),
             AxisLine("rx", "follower", 1.0, 0.0, "force/torque limit", reacting=True)]
    text = axis_text(lines)
    assert text.splitlines() == [
        "y: path  +0.5 N  +0.0 mm/s",
        "z: force_tracking  +10.0 N  -0.3 mm/s",
        "rz: spring  -0.2 Nm  +2.0 deg/s  [max travel]",
        "rx: follower  +1.0 Nm  +0.0 deg/s  (reacting)",
    ]
    assert axis_text([AxisLine("x", "none", 0.0, 0.0)]) == "no law"
    stale = axis_text([], "stale wrench", "no wrench for 0.2 s")
    assert stale.endswith("SAFETY: stale wrench (no wrench for 0.2 s)")


def test_the_speed_cap_line_says_the_cap_and_region_and_when_it_slows_the_motion():
    assert cap_text(1.3682, "hand", False) == "speed cap 1.37 m/s (hand, ISO/TS 15066)"
    assert cap_text(0.157, "face", True) == "CAPPED at 0.16 m/s (face, ISO/TS 15066)"
    assert cap_text(math.inf, "hand", False) == "" and cap_text(0.5, "off", False) == ""


def test_the_velocity_arrow_starts_at_the_tool_and_is_two_seconds_of_motion_long():
    start, end = velocity_arrow((0.4, 0.1, 0.3), (0.0, 0.0, -0.05))
    assert np.allclose(start, (0.4, 0.1, 0.3)) and np.allclose(end, (0.4, 0.1, 0.3 - ARROW_SECONDS * 0.05))
    assert velocity_arrow((0, 0, 0), (1e-5, 0, 0)) is None  # at rest: nothing drawn
    assert velocity_arrow((0, 0, 0), (math.nan, 0, 0)) is None


def test_the_obstacle_comes_from_the_robot_packages_scene_and_a_bad_one_draws_nothing():
    scene = yaml.safe_load((SRC / "ur5_custom" / "config" / "sim.yaml").read_text())
    box = obstacle_box(scene)
    assert box is not None and box.position == pytest.approx(scene["obstacle"]["position"])
    assert box.size == pytest.approx(scene["obstacle"]["size"])
    assert obstacle_box({}) is None
    assert obstacle_box({"obstacle": {"position": [1, 2], "size": [1, 1, 1]}}) is None
    assert obstacle_box({"obstacle": {"position": "here", "size": [1, 1, 1]}}) is None


@pytest.mark.parametrize("rpy", [(0.0, 0.0, math.pi / 2), (0.3, -0.7, 2.1)])
def test_the_box_orientation_follows_urdfs_roll_pitch_yaw(rpy):
    """URDF: roll about X, then pitch about Y, then yaw about Z (fixed axes): Rz(yaw) Ry(pitch) Rx(roll)."""
    def about(axis: int, angle: float) -> np.ndarray:
        c, s = math.cos(angle), math.sin(angle)
        i, j = [k for k in range(3) if k != axis]
        r = np.eye(3)
        r[i, i], r[i, j], r[j, i], r[j, j] = c, -s, s, c
        return r if axis != 1 else r.T  # about Y the sine's sign is the other way round

    expected = about(2, rpy[2]) @ about(1, rpy[1]) @ about(0, rpy[0])
    x, y, z, w = Box((0, 0, 0), rpy, (1, 1, 1)).quaternion()
    assert np.allclose(pin.Quaternion(w, x, y, z).matrix(), expected)


def test_a_trail_keeps_points_a_millimetre_apart_and_starts_over_after_a_pause():
    trail = Trail(spacing=0.001, limit=5, gap=1.0)
    for k in range(4):
        trail.add(0.1 * k, (0.0005 * k, 0.0, 0.0))  # half a millimetre apart: every other one kept
    assert trail.points == [(0.0, 0.0, 0.0), (0.001, 0.0, 0.0)]
    for k in range(10):
        trail.add(0.5 + 0.1 * k, (0.01 * k, 0.0, 0.0))
    assert len(trail.points) == 5 and trail.points[-1] == (0.09, 0.0, 0.0)  # the newest kept
    trail.add(5.0, (1.0, 1.0, 1.0))  # a new replay
    assert trail.points == [(1.0, 1.0, 1.0)]
