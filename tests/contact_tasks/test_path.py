"""A path of poses run at a set speed (contact_tasks.path): where its reference is, how fast, how far a point
is from it, and the paths it refuses."""

from __future__ import annotations

import math

import numpy as np
import pytest
from contact_tasks.path import PosePath, quaternion_slerp
from contact_tasks.task import TaskError

DOWN = (1.0, 0.0, 0.0, 0.0)  # the tool pointing down: turned half a turn about x


def _about_y(angle: float) -> tuple[float, float, float, float]:
    """DOWN tilted `angle` about the base's y."""
    qy = (0.0, math.sin(angle / 2), 0.0, math.cos(angle / 2))
    x1, y1, z1, w1 = qy
    x2, y2, z2, w2 = DOWN
    return (w1 * x2 + x1 * w2 + y1 * z2 - z1 * y2, w1 * y2 - x1 * z2 + y1 * w2 + z1 * x2,
            w1 * z2 + x1 * y2 - y1 * x2 + z1 * w2, w1 * w2 - x1 * x2 - y1 * y2 - z1 * z2)


def test_the_reference_runs_the_segments_at_the_speed_and_ends_still():
    path = PosePath([(0, 0, 0, *DOWN), (0.03, 0, 0, *DOWN), (0.03, 0.04, 0, *DOWN)], speed=0.01)
    assert path.length == pytest.approx(0.07) and path.duration == pytest.approx(7.0)
    mid = path.at(1.5)
    assert mid.position == pytest.approx((0.015, 0.0, 0.0)) and mid.twist[:3] == pytest.approx((0.01, 0, 0))
    assert mid.segment == 0 and mid.arc == pytest.approx(0.015) and not mid.done
    later = path.at(5.0)
    assert later.position == pytest.approx((0.03, 0.02, 0.0))
    assert later.twist[:3] == pytest.approx((0, 0.01, 0))
    assert later.segment == 1
    end = path.at(9.0)
    assert end.done and end.position == pytest.approx((0.03, 0.04, 0.0)) and end.twist == (0.0,) * 6
    assert path.at(-1.0).position == pytest.approx((0.0, 0.0, 0.0))


def test_orientations_turn_by_slerp_and_a_fast_turn_slows_its_segment():
    tilt = 0.4
    path = PosePath([(0, 0, 0, *DOWN), (0.01, 0, 0, *_about_y(tilt))], speed=0.01, angular_speed=0.2)
    assert path.duration == pytest.approx(tilt / 0.2)  # the turn takes longer than the 1 s of travel
    half = path.at(path.duration / 2)
    assert np.allclose(half.quaternion, _about_y(tilt / 2), atol=1e-9) or np.allclose(
        half.quaternion, -np.asarray(_about_y(tilt / 2)), atol=1e-9)
    assert half.twist[3:] == pytest.approx((0.0, 0.2, 0.0))  # about the base's y at the angular speed
    assert half.twist[:3] == pytest.approx((0.01 / path.duration, 0.0, 0.0))


def test_a_ramp_speeds_up_and_slows_down_at_constant_acceleration():
    path = PosePath([(0, 0, 0, *DOWN), (0.1, 0, 0, *DOWN)], speed=0.01, ramp=2.0)
    assert path.duration == pytest.approx(12.0)  # 10 s at full speed, plus half of each ramp
    assert path.at(1.0).twist[0] == pytest.approx(0.005) and path.at(1.0).position[0] == pytest.approx(0.0025)
    assert path.at(2.0).position[0] == pytest.approx(0.01) and path.at(6.0).twist[0] == pytest.approx(0.01)
    assert path.at(11.0).twist[0] == pytest.approx(0.005)
    assert path.at(11.0).position[0] == pytest.approx(0.1 - 0.0025)
    assert path.at(12.0).done and path.at(12.0).position[0] == pytest.approx(0.1)


def test_slerp_takes_the_short_way():
    a = np.array(DOWN)
    b = -np.array(_about_y(0.2))  # the same rotation as _about_y(0.2), the other sign
    q = quaternion_slerp(a, b, 0.5)
    angle = 2 * math.acos(min(1.0, abs(float(q @ a))))
    assert angle == pytest.approx(0.1)


def test_nearest_gives_the_arc_and_the_offset():
    path = PosePath([(0, 0, 0, *DOWN), (0.1, 0, 0, *DOWN)], speed=0.01)
    arc, off, segment = path.nearest((0.04, 0.003, -0.002))
    assert arc == pytest.approx(0.04) and off == pytest.approx((0.0, 0.003, -0.002)) and segment == 0
    assert path.tangent(0) == pytest.approx((1.0, 0.0, 0.0))


@pytest.mark.parametrize(("poses", "speed", "said"), [
    ([(0, 0, 0, *DOWN)], 0.01, "at least two poses"),
    ([(0, 0, 0, *DOWN), (0.1, 0, 0, 1, 0, 0)], 0.01, "at least two poses of 7 numbers"),
    ([(0, 0, 0, *DOWN), (0.1, 0, math.nan, *DOWN)], 0.01, "not finite"),
    ([(0, 0, 0, *DOWN), (0.1, 0, 0, 0, 0, 0, 0)], 0.01, "pose 1: its quaternion is zero"),
    ([(0, 0, 0, *DOWN), (0, 0, 0, *DOWN)], 0.01, "poses 0 and 1 are the same"),
    ([(0, 0, 0, *DOWN), (0.1, 0, 0, *DOWN)], 0.0, "speed must be positive"),
])
def test_a_path_that_cannot_be_run_is_refused(poses, speed, said):
    with pytest.raises(TaskError, match=said):
        PosePath(poses, speed)
