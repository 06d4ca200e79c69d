"""Fixtures on the obstacle block: a plate with a square, chamfered hole, built from boxes (MuJoCo
collides meshes by their convex hull, which would fill the hole); the free hand in the block's place. No
MuJoCo here: the boxes are data that `scene._add_environment` turns into geoms, so the geometry is tested
on its own (README, Fixtures).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from mujoco_driver.config import Box, Hand, Hole

__all__ = ["FixtureBox", "free_hand", "hole_boxes", "hole_offset", "hole_pose"]


@dataclass(frozen=True)
class FixtureBox:
    """A box geom in the world: name, half extents [m], centre [m], orientation quaternion (w, x, y, z)."""

    name: str
    half: tuple[float, float, float]
    pos: tuple[float, float, float]
    quat: tuple[float, float, float, float]


def free_hand(block: Box) -> Hand:
    """The free hand (config.Hand `free`) with its top where `block`'s top centre is."""
    hand = Hand(free=True)
    x, y, z = block.position
    return replace(hand, at=(x, y, z + block.size[2] / 2.0 - hand.size[2]))


def hole_offset(seed: int, spread: float, yaw_spread: float) -> tuple[float, float, float]:
    """A pseudo-random offset of the hole from its nominal pose: (dx, dy) uniform in a disc of radius
    `spread` [m], yaw uniform in +-`yaw_spread` [rad]; the same for the same seed."""
    rng = np.random.default_rng(seed)
    radius, angle = spread * math.sqrt(float(rng.random())), 2.0 * math.pi * float(rng.random())
    yaw = yaw_spread * (2.0 * float(rng.random()) - 1.0)
    return (radius * math.cos(angle), radius * math.sin(angle), yaw)


# name, half extents, centre, the axis a chamfer box is turned about ('' for none)
_Part = tuple[str, tuple[float, float, float], tuple[float, float, float], str]


def _ring(name: str, a: float, plate: float, z0: float, z1: float) -> list[_Part]:
    """Four boxes filling a square plate of half side `plate` around a square opening of half side `a`,
    between heights z0 < z1 (hole frame)."""
    t, zc, w = (z1 - z0) / 2.0, (z0 + z1) / 2.0, (plate - a) / 2.0
    c = (a + plate) / 2.0
    return [
        (f"{name}_east", (w, plate, t), (c, 0.0, zc), ""),
        (f"{name}_west", (w, plate, t), (-c, 0.0, zc), ""),
        (f"{name}_north", (a, w, t), (0.0, c, zc), ""),
        (f"{name}_south", (a, w, t), (0.0, -c, zc), ""),
    ]


def hole_pose(block: Box, hole: Hole) -> tuple[float, float, float, float]:
    """Where the hole truly is: its centre's x, y and the plate's top z in the scene's frame [m], its yaw
    [rad] (the block's turned by the offset's)."""
    dx, dy, dyaw = hole.offset
    top = block.position[2] + block.size[2] / 2.0 + hole.depth
    return block.position[0] + dx, block.position[1] + dy, top, block.rpy[2] + dyaw


def hole_boxes(block: Box, hole: Hole) -> list[FixtureBox]:
    """The plate lying on the block's top, its hole at the top's centre moved by `hole.offset`.

    The hole's bottom is the block's top; its opening is `peg + clearance` wide and widens by `chamfer` on
    each side at the top, the 45-degree chamfer made of boxes turned about the edges. A tilted hole turns the
    whole plate about the top's centre (its edges then dip into the block or stand above it: static geoms
    do not collide with each other).
    """
    if any(abs(a) > 1e-9 for a in block.rpy[:2]):
        raise ValueError("the hole fixture needs a level obstacle (rpy roll and pitch 0)")
    half_hole, chamfer, depth = (hole.peg + hole.clearance) / 2.0, hole.chamfer, hole.depth
    plate = hole.plate / 2.0
    parts = _ring("hole_plate", half_hole, plate, -depth, -chamfer if chamfer > 0.0 else 0.0)
    if chamfer > 0.0:
        parts += _ring("hole_rim", half_hole + chamfer, plate, -chamfer, 0.0)
        edge, side = half_hole + chamfer, chamfer / math.sqrt(2.0)
        parts += [  # squares turned 45 degrees: one face is the chamfer, the rest lies inside the plate
            ("hole_chamfer_east", (side, edge, side), (edge, 0.0, -chamfer), "y"),
            ("hole_chamfer_west", (side, edge, side), (-edge, 0.0, -chamfer), "y"),
            ("hole_chamfer_north", (edge, side, side), (0.0, edge, -chamfer), "x"),
            ("hole_chamfer_south", (edge, side, side), (0.0, -edge, -chamfer), "x"),
        ]
    x, y, top, yaw = hole_pose(block, hole)
    origin = np.array([x, y, top])
    roll, pitch = hole.tilt
    # The hole frame: the yaw, then the tilt about its own x and y axes, all through the top's centre.
    frame = _multiply(_multiply((math.cos(yaw / 2.0), 0.0, 0.0, math.sin(yaw / 2.0)),
                                (math.cos(roll / 2.0), math.sin(roll / 2.0), 0.0, 0.0)),
                      (math.cos(pitch / 2.0), 0.0, math.sin(pitch / 2.0), 0.0))
    turn = _matrix(frame)
    boxes = []
    q = math.cos(math.pi / 8.0), math.sin(math.pi / 8.0)
    for name, half, local, axis in parts:
        pos = origin + turn @ np.array(local)
        quat = frame
        if axis:  # 45 degrees about the hole frame's x or y axis
            quat = _multiply(frame, (q[0], q[1], 0.0, 0.0) if axis == "x" else (q[0], 0.0, q[1], 0.0))
        boxes.append(FixtureBox(name, half, (float(pos[0]), float(pos[1]), float(pos[2])), quat))
    return boxes


def _matrix(q: tuple[float, float, float, float]) -> np.ndarray:
    """The rotation matrix of a unit quaternion (w, x, y, z)."""
    w, x, y, z = q
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
                     [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
                     [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]])


def _multiply(a: tuple[float, ...], b: tuple[float, ...]) -> tuple[float, float, float, float]:
    """Quaternion product a b, (w, x, y, z)."""
    w1, x1, y1, z1 = a
    w2, x2, y2, z2 = b
    return (w1 * w2 - x1 * x2 - y1 * y2 - z1 * z2, w1 * x2 + x1 * w2 + y1 * z2 - z1 * y2,
            w1 * y2 - x1 * z2 + y1 * w2 + z1 * x2, w1 * z2 + x1 * y2 - y1 * x2 + z1 * w2)
