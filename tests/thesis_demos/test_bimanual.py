"""The bimanual demonstration's pure side (thesis_demos.bimanual): the holder's straight move, the laws, and
the verdict on what a run recorded."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from thesis_demos.bimanual import (
    BIMANUAL_FORCE,
    BimanualRecording,
    hold_laws,
    judge,
    reach_laws,
    scene_args,
)
from thesis_demos.scenarios import COMPLIANT_MOVE, SPRING
from thesis_demos.stack_client import Names


def test_the_reach_is_one_straight_line_at_the_speed_of_its_longest_axis():
    laws = reach_laws(np.array([-0.15, 0.2, 0.0005]), speed=0.04)
    assert set(laws) == {"x", "y"}  # under 1 mm: held
    x, y = laws["x"], laws["y"]
    assert x.law == y.law == COMPLIANT_MOVE
    assert (x.velocity, y.velocity) == pytest.approx((-0.03, 0.04))  # both end together
    assert (x.max_travel, y.max_travel) == pytest.approx((0.15, 0.2))
    assert reach_laws(np.zeros(3)) == {}


def test_the_holder_springs_on_z_only_and_gives_way_a_few_mm_under_the_press():
    (axis, law), = hold_laws().items()
    assert axis == "z" and law.law == SPRING
    sink = BIMANUAL_FORCE / (law.damping * law.stiffness)  # contact_control README, the spring law
    assert 0.001 <= sink <= 0.005


def test_the_scene_clears_both_tables_and_gives_the_holder_its_plate():
    assert scene_args("left", "right") == {"left.tool": "plate", "left.fixture": "clear",
                                           "right.fixture": "clear"}


def test_names_within_a_namespace_are_absolute_and_keep_an_empty_base_frame():
    names = Names().within("/right/")
    assert names.configure_laws == "/right/configure_laws"
    assert names.contact_control == "/right/contact_control_node" and names.base_frame == ""
    assert names.tf_prefix == "/right/tf_prefix"  # read where that arm's launch set it, not nearest this node


def _recording(**changes) -> BimanualRecording:
    """A good run: 10 N from 0.5 s of an 8 s slide, the plate 1.5 mm down meanwhile, back to 0.3 mm."""
    t = np.arange(0.0, 8.0, 0.002)
    force = np.full_like(t, 10.0)
    force[t < 0.3] = 8.0  # the slide's start dips: before the judged part
    rec = BimanualRecording(force_t=t, force=force, holder_t=t, holder_z=np.full_like(t, 0.2485),
                            slide_end=8.0, held_z=0.25, returned_z=0.2497, outcome="succeeded", message="ran")
    return dataclasses.replace(rec, **changes)


def test_a_good_run_passes_and_says_each_number():
    verdict = judge(_recording())
    assert verdict.passed, verdict.lines
    assert any("10.00..10.00 N" in line for line in verdict.lines)
    assert any("gave way 1.5 mm" in line for line in verdict.lines)
    assert any("back within 0.30 mm" in line for line in verdict.lines)


def _dip(rec: BimanualRecording, at: float, to: float) -> np.ndarray:
    force = rec.force.copy()
    force[(rec.force_t > at) & (rec.force_t < at + 0.1)] = to
    return force


@pytest.mark.parametrize(("changes", "words"), [
    ({"outcome": "failed"}, "path server: failed"),
    ({"force": _dip(_recording(), 4.0, 8.2)}, "8.20..10.00 N"),  # a 100 ms dip within the slide
    ({"force": _dip(_recording(), 4.0, 11.8)}, "10.00..11.80 N"),
    ({"holder_z": np.full(4000, 0.2497)}, "gave way 0.3 mm"),  # it did not give way
    ({"holder_z": np.where(np.arange(4000) // 100 == 20, 0.2455, 0.2485)}, "within 3.00 mm"),  # a jolt
    ({"returned_z": 0.2485}, "back within 1.50 mm"),
    ({"force_t": np.arange(0.0, 0.4, 0.002), "force": np.full(200, 10.0)}, "no force"),
])
def test_a_run_fails_on_each_of_its_criteria_naming_it(changes, words):
    verdict = judge(_recording(**changes))
    assert not verdict.passed
    assert any(words in line for line in verdict.lines), verdict.lines
