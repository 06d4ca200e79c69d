"""The serial manipulators of example-robot-data and a flange for each, read from the installed package.

Pure (no ROS): `survey()` parses every URDF under example-robot-data's robots/ and keeps the serial
manipulators: from the root, one chain of at least MIN_ARM_JOINTS movable joints with nothing beside it (a
robot whose joints branch into legs, arms or wheels before the chain ends is not one; its arm is added with
BASE=). Joints at the chain's end named like a gripper (gripper, finger, jaw, hand) are the gripper, not the
arm. The flange (TIP) is found below the last arm joint's link through fixed joints, not past a gripper's
base: the deepest link without geometry (a flange or tool frame), else the deepest link. The robot_setup
README (Every arm of example-robot-data) has the table `scripts/try_all_arms` prints.
"""

from __future__ import annotations

import os
import re
import xml.etree.ElementTree as ET
from dataclasses import dataclass

from control_stack.description import find_example_robot_data

__all__ = ["MIN_ARM_JOINTS", "Arm", "NotAnArm", "arms", "survey"]

# An arm for the demonstrations moves the tool in 3-D and turns it: fewer joints than this cannot hold the
# tool down while it travels (a choice: 4-joint SCARA arms would need a planar tool law).
MIN_ARM_JOINTS = 5
_GRIPPER = re.compile(r"grip|finger|jaw|hand", re.IGNORECASE)
_FIXED = ("fixed",)


@dataclass(frozen=True)
class Arm:
    """A serial manipulator of example-robot-data.

    Attributes:
        urdf: Path under example-robot-data's robots/ (make robot's URDF=).
        joints: The arm's movable joints, root to flange.
        tip: The flange link (make robot's TIP=).
        gripper: Movable joints after the flange (held or removed by make robot).
    """

    urdf: str
    joints: tuple[str, ...]
    tip: str
    gripper: tuple[str, ...] = ()

    @property
    def name(self) -> str:
        """A package name for it: the file's name in lower case, letters, digits and _ only."""
        stem = os.path.splitext(os.path.basename(self.urdf))[0].lower()
        return re.sub(r"[^a-z0-9_]", "_", stem).strip("_")


@dataclass(frozen=True)
class NotAnArm:
    """A URDF of the library that is not a serial manipulator, and why."""

    urdf: str
    reason: str


def _movable(jtype: str | None) -> bool:
    return jtype not in (None, "fixed", "floating", "planar")


def _classify(rel: str, robot: ET.Element) -> Arm | NotAnArm:
    children: dict[str, list[tuple[str, ET.Element]]] = {}
    child_links = set()
    for joint in robot.findall("joint"):
        parent, child = joint.find("parent"), joint.find("child")
        if parent is None or child is None:
            return NotAnArm(rel, f"joint {joint.get('name')!r} lacks its parent or child")
        children.setdefault(parent.get("link", ""), []).append((child.get("link", ""), joint))
        child_links.add(child.get("link", ""))
    links = {link.get("name", ""): link for link in robot.findall("link")}
    roots = [name for name in links if name not in child_links]
    if len(roots) != 1:
        return NotAnArm(rel, f"{len(roots)} root links")

    def movable_below(link: str) -> int:
        return sum(_movable(j.get("type")) + movable_below(c) for c, j in children.get(link, []))

    chain: list[ET.Element] = []
    link = roots[0]
    while True:
        branches = [(c, j) for c, j in children.get(link, []) if _movable(j.get("type")) or movable_below(c)]
        if len(branches) != 1:
            break
        link, joint = branches[0]
        if _movable(joint.get("type")):
            chain.append(joint)
    gripper: list[ET.Element] = []
    while chain and _GRIPPER.search(chain[-1].get("name", "")):
        gripper.insert(0, chain.pop())
    total = sum(_movable(j.get("type")) for j in robot.findall("joint"))
    beside = total - len(chain) - len(gripper) - movable_below(link)
    if len(chain) < MIN_ARM_JOINTS:
        return NotAnArm(rel, f"{len(chain)} joints in series from the root (an arm has {MIN_ARM_JOINTS} or "
                             "more)")
    if beside > 0:
        return NotAnArm(rel, f"{beside} movable joints beside the chain (legs, wheels, other limbs)")
    last = chain[-1].find("child")
    flange = last.get("link", "") if last is not None else ""
    # Below the last arm joint's link, through fixed joints and not past a gripper's base (a link with moving
    # children): the deepest link without geometry (a flange or tool frame), else the deepest link (the
    # gripper's base: make robot removes what is below it).
    best: dict[bool, tuple[int, str]] = {True: (0, flange), False: (0, flange)}
    stack = [(flange, 0)]
    while stack:
        here, level = stack.pop()
        for below, fixed in children.get(here, []):
            if fixed.get("type") in _FIXED and below in links:
                bare = not links[below].findall("visual") and not links[below].findall("collision")
                for kind in (True, False) if bare else (False,):
                    if level + 1 > best[kind][0]:
                        best[kind] = (level + 1, below)
                if not any(_movable(j.get("type")) for _, j in children.get(below, [])):
                    stack.append((below, level + 1))  # not into a gripper: its base is as far as it goes
    tip = best[True][1] if best[True][0] > 0 else best[False][1]
    after = [j.get("name", "") for j in gripper] + [
        j.get("name", "") for j in robot.findall("joint") if _movable(j.get("type"))
        and j not in chain and j not in gripper]
    return Arm(rel, tuple(j.get("name", "") for j in chain), tip, tuple(after))


def survey(erd_dir: str | None = None) -> list[Arm | NotAnArm]:
    """Every URDF under example-robot-data's robots/, sorted by path: an Arm or why it is not one."""
    robots = os.path.join(erd_dir or find_example_robot_data(), "robots")
    out: list[Arm | NotAnArm] = []
    for folder, _, files in sorted(os.walk(robots)):
        for name in sorted(f for f in files if f.endswith(".urdf")):
            rel = os.path.relpath(os.path.join(folder, name), robots)
            try:
                robot = ET.parse(os.path.join(folder, name)).getroot()
            except ET.ParseError as exc:
                out.append(NotAnArm(rel, f"not XML: {exc}"))
                continue
            out.append(_classify(rel, robot))
    return out


def arms(erd_dir: str | None = None) -> list[Arm]:
    """The serial manipulators of the library."""
    return [a for a in survey(erd_dir) if isinstance(a, Arm)]
