"""The hole fixture (mujoco_driver.fixtures): a 10 mm square peg fits its 10.4 mm hole, touches a wall past
the clearance, rests on the 45-degree chamfer at the right depth, and stands on the plate elsewhere."""

from __future__ import annotations

import math

import mujoco
import pytest
from mujoco_driver.fixtures import hole_boxes, hole_offset

from mujoco_driver.config import Box, Hole

BLOCK = Box(position=(0.6, 0.1, 0.065), size=(0.15, 0.15, 0.13), rpy=(0.0, 0.0, 0.3))
HOLE = Hole(offset=(0.003, -0.002, 0.02))
TOP = 0.13 + HOLE.depth  # the plate's top [m]
YAW = 0.3 + 0.02


def _peg_touches(block: Box, hole: Hole, centre: list[float], quat: list[float]) -> bool:
    """Whether the peg (10 mm square, 40 mm long) with its centre and orientation there touches the plate."""
    spec = mujoco.MjSpec()
    for box in hole_boxes(block, hole):
        spec.worldbody.add_geom(type=mujoco.mjtGeom.mjGEOM_BOX, size=list(box.half), pos=list(box.pos),
                                quat=list(box.quat))
    peg = spec.worldbody.add_body(pos=centre, quat=quat)
    peg.add_freejoint()
    peg.add_geom(type=mujoco.mjtGeom.mjGEOM_BOX, size=[0.005, 0.005, 0.02])
    model = spec.compile()
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    return any(data.contact[i].dist < 0.0 for i in range(data.ncon))


def touches(x: float, y: float, bottom: float) -> bool:
    """Whether the peg, turned like the hole, with its bottom face at `bottom`, centred at (x, y) in the
    hole's own axes from its centre, touches the fixture."""
    c, s = math.cos(YAW), math.sin(YAW)
    centre = [0.6 + 0.003 + c * x - s * y, 0.1 - 0.002 + s * x + c * y, bottom + 0.02]
    return _peg_touches(BLOCK, HOLE, centre, [math.cos(YAW / 2), 0.0, 0.0, math.sin(YAW / 2)])


def test_the_peg_fits_the_hole_within_its_clearance_and_touches_a_wall_beyond_it():
    assert not touches(0.0, 0.0, TOP - 0.015)
    assert not touches(0.00015, -0.00015, TOP - 0.015)  # within the 0.2 mm either side
    assert touches(0.0003, 0.0, TOP - 0.015)
    assert touches(0.0, -0.0003, TOP - 0.015)


def test_the_peg_rests_on_the_chamfer_at_its_depth_and_on_the_plate_beyond_it():
    # 0.8 mm off centre the peg's edge is 5.8 mm out, over the chamfer, whose surface there is 0.4 mm down.
    assert not touches(0.0008, 0.0, TOP - 0.0003)
    assert touches(0.0008, 0.0, TOP - 0.0005)
    assert not touches(0.0, 0.0008, TOP - 0.0003)
    assert touches(0.0, 0.0008, TOP - 0.0005)
    # 2 mm off it stands on the plate's top.
    assert not touches(0.002, 0.0, TOP + 0.0001)
    assert touches(0.002, 0.0, TOP - 0.0001)


def test_the_seeded_offset_is_within_its_spread_and_the_same_for_the_same_seed():
    offsets = [hole_offset(seed, 0.004, 0.035) for seed in range(200)]
    assert all(math.hypot(dx, dy) <= 0.004 and abs(yaw) <= 0.035 for dx, dy, yaw in offsets)
    assert max(math.hypot(dx, dy) for dx, dy, _ in offsets) > 0.0035  # the disc's edge is reached
    assert hole_offset(7, 0.004, 0.035) == offsets[7]


def _peg_in(hole: Hole, tilted: bool, depth: float) -> bool:
    """Whether the peg, its tip `depth` down the axis of `hole` (at the level block's top centre) and turned
    with the hole's tilt (or upright), touches the plate."""
    roll = hole.tilt[0] if tilted else 0.0
    top = (0.6, 0.1, 0.13 + hole.depth)
    axis = (0.0, math.sin(hole.tilt[0]), -math.cos(hole.tilt[0]))  # down the hole (a roll only)
    up = (0.0, -math.sin(roll), math.cos(roll))
    centre = [top[i] + depth * axis[i] + 0.02 * up[i] for i in range(3)]
    block = Box(position=(0.6, 0.1, 0.065), size=(0.15, 0.15, 0.13))
    return _peg_touches(block, hole, centre, [math.cos(roll / 2), math.sin(roll / 2), 0.0, 0.0])


def test_a_tilted_hole_takes_the_peg_turned_with_it_and_wedges_it_upright():
    hole = Hole(clearance=0.0001, tilt=(math.radians(3.0), 0.0))
    assert not _peg_in(hole, tilted=True, depth=0.015)
    assert _peg_in(hole, tilted=False, depth=0.015)  # 0.1 mm allows 0.4 degrees over 15 mm
    level = Hole(clearance=0.0001)
    assert not _peg_in(level, tilted=False, depth=0.015)


def test_a_tilt_over_its_limit_is_refused():
    from mujoco_driver.params import DriverParamError, DriverSettings, load_scene

    scene = {"start_pose": [0.0], "servo": {"kp": 1.0, "kv": 1.0},
             "obstacle": {"position": [0.5, 0.0, 0.05], "size": [0.1, 0.1, 0.1]}}
    settings = DriverSettings.from_params({"fixture": "hole", "hole_tilt": [0.05, -0.02], "scene": scene})
    cfg = load_scene(settings)
    assert cfg.hole is not None and cfg.hole.tilt == (0.05, -0.02)
    with pytest.raises(DriverParamError, match="hole_tilt"):
        load_scene(DriverSettings.from_params({"fixture": "hole", "hole_tilt": [0.0, 0.2], "scene": scene}))


def test_a_tilted_block_is_refused():
    with pytest.raises(ValueError, match="level obstacle"):
        hole_boxes(Box(position=(0.0, 0.0, 0.0), size=(0.1, 0.1, 0.1), rpy=(0.1, 0.0, 0.0)), HOLE)


def test_the_tilted_fixture_turns_the_block_about_y_and_needs_a_block():
    from mujoco_driver.params import DriverParamError, DriverSettings, load_scene

    scene = {"start_pose": [0.0], "servo": {"kp": 1.0, "kv": 1.0},
             "obstacle": {"position": [0.5, 0.0, 0.05], "size": [0.1, 0.1, 0.1], "rpy": [0.0, 0.1, 0.2]}}
    cfg = load_scene(DriverSettings.from_params({"fixture": "tilted", "scene": scene}))
    assert cfg.obstacle is not None
    assert cfg.obstacle.rpy == pytest.approx((0.0, 0.1 + math.radians(15.0), 0.2), abs=1e-4)
    cfg = load_scene(DriverSettings.from_params({"fixture": "tilted", "surface_tilt": 0.3, "scene": scene}))
    assert cfg.obstacle is not None and cfg.obstacle.rpy[1] == pytest.approx(0.4)
    del scene["obstacle"]
    with pytest.raises(DriverParamError, match="no obstacle block to stand for the part"):
        load_scene(DriverSettings.from_params({"fixture": "tilted", "scene": scene}))


def _height(kind: str, x: float, y: float, **params) -> float:
    """The surface's height [m] under (x, y): a ray cast down onto the scene `load_scene` makes with the
    `kind` fixture on a 0.15 x 0.15 x 0.13 block centred at (0.6, 0.1)."""
    import numpy as np
    from mujoco_driver.params import DriverSettings, load_scene
    from mujoco_driver.scene import _add_environment

    scene = {"start_pose": [0.0], "servo": {"kp": 1.0, "kv": 1.0},
             "obstacle": {"position": [0.6, 0.1, 0.065], "size": [0.15, 0.15, 0.13]}}
    cfg = load_scene(DriverSettings.from_params({"fixture": kind, "scene": scene, **params}))
    spec = mujoco.MjSpec()
    _add_environment(spec, cfg)
    model = spec.compile()
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    geom = np.array([-1], dtype=np.int32)
    down = np.array([0.0, 0.0, -1.0])
    distance = mujoco.mj_ray(model, data, np.array([x, y, 1.0]), down, None, 1, -1, geom)
    assert model.geom(geom[0]).name == "obstacle"
    return 1.0 - distance


@pytest.mark.parametrize(("kind", "radius"), [("cylinder", 0.25), ("sphere", 0.3)])
def test_a_curved_part_stands_in_the_blocks_place_moved_by_its_offset(kind, radius):
    offset = (0.004, -0.003, 0.002)
    args = {"surface_offset": list(offset)}
    top = (0.6 + offset[0], 0.1 + offset[1], 0.13 + offset[2])
    assert _height(kind, top[0], top[1], **args) == pytest.approx(top[2], abs=1e-6)
    # 60 mm along x the surface has fallen as a circle of the radius says; along y only the sphere's has
    fallen = radius - math.sqrt(radius**2 - 0.06**2)
    assert _height(kind, top[0] + 0.06, top[1], **args) == pytest.approx(top[2] - fallen, abs=1e-6)
    across = _height(kind, top[0], top[1] + 0.06, **args)
    assert across == pytest.approx(top[2] - (fallen if kind == "sphere" else 0.0), abs=1e-6)


def test_a_seeded_surface_is_off_by_up_to_10_mm_the_same_way_for_the_same_seed():
    from mujoco_driver.params import DriverSettings, load_scene

    scene = {"start_pose": [0.0], "servo": {"kp": 1.0, "kv": 1.0},
             "obstacle": {"position": [0.6, 0.1, 0.065], "size": [0.15, 0.15, 0.13]}}
    offsets = [load_scene(DriverSettings.from_params({"fixture": "cylinder", "surface_seed": seed,
                                                      "scene": scene})).surface.offset for seed in (1, 2, 1)]
    assert offsets[0] == offsets[2] != offsets[1]
    assert all(0.0 < abs(d) <= 0.01 for offset in offsets for d in offset)
    assert _height("sphere", 0.6, 0.1, surface_seed=1) != pytest.approx(0.13, abs=1e-4)


def test_the_drivers_surface_truth_says_where_the_part_is():
    from mujoco_driver.params import DriverSettings, load_scene
    from mujoco_driver.scene import surface_truth

    scene = {"start_pose": [0.0], "servo": {"kp": 1.0, "kv": 1.0},
             "obstacle": {"position": [0.6, 0.1, 0.065], "size": [0.15, 0.15, 0.13]}}

    def truth(**params):
        cfg = load_scene(DriverSettings.from_params({"scene": scene, **params}))
        return surface_truth(cfg.obstacle, cfg.surface)

    got = truth(fixture="cylinder", surface_offset=[0.004, -0.003, 0.005])
    assert got["kind"] == "cylinder" and got["radius"] == 0.25
    assert got["top"] == pytest.approx([0.604, 0.097, 0.135])
    assert got["friction"] == pytest.approx(0.3)
    tilted = truth(fixture="tilted")
    assert tilted["rpy"] == pytest.approx([0.0, 0.2618, 0.0])
    # the top face's centre: the block's centre plus half its height along the turned z axis
    half, tilt = 0.065, 0.2618
    assert tilted["top"] == pytest.approx([0.6 + half * math.sin(tilt), 0.1, 0.065 + half * math.cos(tilt)])
