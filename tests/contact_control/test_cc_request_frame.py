"""ConfigureLaws' `frame`: the laws act along a tf frame looked up every cycle (one on the tool turns with
it); an unknown frame is refused and changes nothing; a move in another frame stops first."""

from __future__ import annotations

import math

import numpy as np
import pytest
from contact_control.axes import LAW_COMPLIANT_MOVE
from contact_control.request import empty_laws_request
from contact_control.stage import ContactStage

from contact_control import load_settings

from .cc_sim import DT, rot


def _pose(R: np.ndarray) -> list[list[float]]:
    T = np.eye(4)
    T[:3, :3] = R
    return T.tolist()


class _World:
    """tf as the stage sees it: base_link fixed, tool0 turned by `turn` (about base x)."""

    def __init__(self) -> None:
        self.turn = math.pi / 2

    def __call__(self, frame: str) -> list[list[float]]:
        if frame == "tool0":
            return _pose(rot([1, 0, 0], self.turn))
        if frame in ("base_link", "ft_sensor"):
            return _pose(np.eye(3))
        raise LookupError(f'"{frame}" passed to lookupTransform does not exist')


def _stage(world: _World) -> ContactStage:
    settings = load_settings({"tare_on_startup": False, "eef_frame": "tool0", "ft_sensor_frame": "ft_sensor",
                              "acceleration_linear": 100.0, "deceleration_linear": 100.0})
    return ContactStage(settings, world)


def _move_along_z(frame: str, speed: float = 0.01):
    req = empty_laws_request()
    req.z.law, req.z.velocity, req.z.damping = LAW_COMPLIANT_MOVE, speed, 1000.0
    req.z.force_limit, req.z.max_travel = 5.0, 0.5
    req.frame = frame
    return req


def _run(stage: ContactStage, t0: float, cycles: int = 50) -> np.ndarray:
    v = None
    for i in range(cycles):
        out = stage.on_wrench((0, 0, 0, 0, 0, 0), "", None, t0 + (i + 1) * DT)
        v = out if out is not None else v
    assert v is not None
    return np.asarray(v)


def test_laws_act_along_the_requested_frame_as_it_turns():
    world = _World()
    stage = _stage(world)
    answer = stage.configure(_move_along_z("tool0"), 0.0, per_axis=True)
    assert answer.ok and "axes of tool0" in answer.message, answer.message
    v = _run(stage, 0.0)
    # tool0's z is base -y when turned 90 degrees about x: the twist (base_link) goes that way
    assert v[:3] == pytest.approx([0.0, -0.01, 0.0], abs=1e-6)
    world.turn = math.pi  # the tool turns on: so do the laws' axes
    v = _run(stage, 1.0)
    assert v[:3] == pytest.approx([0.0, 0.0, -0.01], abs=1e-6)
    assert stage.frame == "tool0"


def test_an_unknown_frame_is_refused_and_changes_nothing():
    stage = _stage(_World())
    assert stage.configure(_move_along_z(""), 0.0, per_axis=True).ok
    running = stage.ctrl.move_id
    answer = stage.configure(_move_along_z("nowhere"), 0.1, per_axis=True)
    assert not answer.ok and "frame: 'nowhere' is not available" in answer.message, answer.message
    assert stage.ctrl.move_active and stage.ctrl.move_id == running and stage.frame == "base_link"
    v = _run(stage, 0.2)
    assert v[:3] == pytest.approx([0.0, 0.0, 0.01], abs=1e-6)  # still along base z


def test_a_move_in_another_frame_starts_from_rest():
    """The running move's speed is along the old frame's axes: it is not carried into the new ones."""
    world = _World()
    settings = load_settings({"tare_on_startup": False, "eef_frame": "tool0", "ft_sensor_frame": "ft_sensor",
                              "acceleration_linear": 0.5, "deceleration_linear": 0.5})
    stage = ContactStage(settings, world)
    assert stage.configure(_move_along_z(""), 0.0, per_axis=True).ok
    assert _run(stage, 0.0)[2] == pytest.approx(0.01, abs=1e-6)
    assert stage.configure(_move_along_z("tool0"), 1.0, per_axis=True).ok
    first = _run(stage, 1.0, cycles=1)
    assert np.linalg.norm(first[:3]) <= 0.5 * DT + 1e-9  # from rest, within the acceleration limit
    assert _run(stage, 1.1)[:3] == pytest.approx([0.0, -0.01, 0.0], abs=1e-6)
    # the same frame again: a bumpless change from the speed it has
    assert stage.configure(_move_along_z("/tool0", 0.02), 1.1 + 50 * DT, per_axis=True).ok
    after = np.linalg.norm(_run(stage, 1.1 + 50 * DT, cycles=1)[:3])
    assert after == pytest.approx(0.01 + 0.5 * DT, abs=1e-6)
