"""Motion patterns (contact_tasks.patterns): where the reference is, how fast it moves, when it ends."""

from __future__ import annotations

import math

import numpy as np
import pytest
from contact_tasks.patterns import evaluate
from contact_tasks.task import Pattern


def test_a_spiral_runs_at_its_speed_and_widens_by_its_pitch_each_turn_until_its_radius():
    spiral = Pattern(type="spiral", pitch=0.002, max_radius=0.006, speed=0.004)
    times = np.arange(0.0, 30.0, 0.001)
    points = [evaluate(spiral, t) for t in times]
    xy = np.array([p.offset[:2] for p in points])
    running = [i for i, p in enumerate(points) if not p.done]
    steps = np.linalg.norm(np.diff(xy[: running[-1]], axis=0), axis=1) / 0.001
    assert steps[50:] == pytest.approx(0.004, rel=0.01)  # along the curve at 4 mm/s
    assert all(math.hypot(*p.twist[:2]) == pytest.approx(0.004, rel=1e-6) for p in points[1 : running[-1]])
    angles = np.unwrap(np.arctan2(xy[1:, 1], xy[1:, 0]))
    radii = np.linalg.norm(xy[1:], axis=1)
    one_turn = np.searchsorted(angles, angles[0] + 2.0 * math.pi)
    assert radii[one_turn] - radii[0] == pytest.approx(0.002, abs=2e-5)
    end = points[running[-1] + 1]
    assert end.done and end.radius == pytest.approx(0.006) and end.twist == (0.0,) * 6
    assert evaluate(spiral, 100.0) == end  # it holds its last point
    length = math.pi * 0.006**2 / 0.002  # an Archimedean spiral's length ~ pi R^2 / pitch
    assert times[running[-1]] == pytest.approx(length / 0.004, rel=0.02)


def test_a_line_moves_along_its_signed_axis_for_its_distance():
    line = Pattern(type="line", axis="-y", distance=0.01, speed=0.02)
    half = evaluate(line, 0.25)
    assert half.offset == pytest.approx((0.0, -0.005, 0.0)) and half.twist[1] == -0.02 and not half.done
    end = evaluate(line, 1.0)
    assert end.offset == pytest.approx((0.0, -0.01, 0.0)) and end.done and end.twist == (0.0,) * 6


@pytest.mark.parametrize("kind", ["lissajous", "wiggle"])
def test_lissajous_and_wiggle_are_sinusoids_with_their_derivatives_until_their_duration(kind):
    pattern = Pattern(type=kind, amplitude=(0.003, 0.002), frequency=(0.5, 0.25), duration=4.0)
    p = evaluate(pattern, 0.5)
    moved = p.offset if kind == "lissajous" else p.rotation
    speed = p.twist[:2] if kind == "lissajous" else p.twist[3:5]
    assert moved[:2] == pytest.approx((0.003, 0.002 * math.sin(math.pi / 4)))
    assert speed == pytest.approx((0.0, 0.002 * 2 * math.pi * 0.25 * math.cos(math.pi / 4)), abs=1e-12)
    assert evaluate(pattern, 5.0).done and not p.done
    assert evaluate(pattern, 5.0).twist == (0.0,) * 6
