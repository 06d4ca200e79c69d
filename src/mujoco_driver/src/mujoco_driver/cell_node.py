"""mujoco_cell node: one MuJoCo world with every arm of a cell, each under its namespace (README, Cells).

Each arm's parameters are where its own driver's would be (``/<arm>/mujoco_driver/``, set by its robot
package's sim.launch with ``with_driver:=false``), its description at ``/<arm>/robot_description``, its tf
prefix at ``/<arm>/tf_prefix``; the cell node's ``~arms`` lists the arms and their base poses in the world.
The loop's settings (real-time factor, /clock) are the first arm's, its lockstep wait at most
CELL_LOCKSTEP_WAIT; ``~viewer`` opens MuJoCo's window on the whole cell. Each arm's tf tree hangs from
``~world_frame`` (static transforms to its prefixed URDF root at its base pose): one tf tree for the cell.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping, Sequence
from typing import Any

import rospy
import tf2_ros
from compliant_common.tf_prefix import TfPrefix
from geometry_msgs.msg import TransformStamped

from mujoco_driver.cell import CellArm, World
from mujoco_driver.cell_file import triple
from mujoco_driver.config import ConfigError
from mujoco_driver.node import ArmSetup, MujocoDriverNode, serve, watch_master
from mujoco_driver.params import DriverParamError, DriverSettings, load_scene, urdf_root_link
from mujoco_driver.ros_arm_port import PortNames
from mujoco_driver.scene import rpy_to_quat

__all__ = ["CellParamError", "base_transforms", "main", "read_arms"]

DRIVER_NAME = "mujoco_driver"  # each arm's driver node name, under its namespace
# [s] wall time: the longest the world waits for one arm's silent stack (README, Lockstep). Every arm's time
# stops meanwhile, so it stays under the stacks' stale-wrench timeouts (contact_control: 0.19-0.25 s): a
# dead stack on one arm must not end another arm's contact move (1 s ended the other arm's follower move).
CELL_LOCKSTEP_WAIT = 0.1


class CellParamError(DriverParamError):
    """A bad ``~arms`` entry or an arm's parameters missing."""


def read_arms(entries: Any) -> list[tuple[str, tuple[float, float, float], tuple[float, float, float]]]:
    """`~arms` as (name, position [m], rpy [rad]) per arm.

    Raises:
        CellParamError: Not a list of mappings with a `name`, an unknown key, or a bad position or rpy.
    """
    if not isinstance(entries, list) or not entries:
        raise CellParamError(f"~arms: expected a list of {{name, position, rpy}}, got {entries!r}")
    arms = []
    for i, entry in enumerate(entries):
        where = f"~arms[{i}]"
        if not isinstance(entry, Mapping) or not isinstance(entry.get("name"), str) or not entry["name"]:
            raise CellParamError(f"{where}: expected a mapping with a name (the arm's namespace), got "
                                 f"{entry!r}")
        unknown = sorted(set(entry) - {"name", "position", "rpy"})
        if unknown:
            raise CellParamError(f"{where}: unknown keys {unknown} (known: name, position, rpy)")
        arms.append((entry["name"].strip("/"), triple(entry, "position", where, CellParamError),
                     triple(entry, "rpy", where, CellParamError)))
    return arms


def _arm(name: str, use_sim_time: bool) -> tuple[DriverSettings, str, TfPrefix]:
    """An arm's driver settings, description and tf prefix from its namespace."""
    params = rospy.get_param(f"/{name}/{DRIVER_NAME}", None)
    if not isinstance(params, dict):
        raise CellParamError(f"arm {name}: no parameters at /{name}/{DRIVER_NAME} (start its robot package's "
                             "sim.launch with ns:={name} with_driver:=false)")
    try:
        settings = DriverSettings.from_params(params, use_sim_time=use_sim_time)
    except DriverParamError as exc:
        raise CellParamError(f"arm {name}: {exc}") from None
    if settings.profile:
        raise CellParamError(f"arm {name}: ~profile {settings.profile!r}: a cell's arms speak this driver's "
                             "own interface")
    key = f"/{name}/{DRIVER_NAME}/robot_description"
    key = key if rospy.has_param(key) else f"/{name}/robot_description"
    if not rospy.has_param(key):
        raise CellParamError(f"arm {name}: /{name}/robot_description is not set (the URDF)")
    return settings, rospy.get_param(key), TfPrefix(str(rospy.get_param(f"/{name}/tf_prefix", "")))


Triple = tuple[float, float, float]


def base_transforms(world_frame: str, roots: Sequence[tuple[str, Triple, Triple]]) -> list[TransformStamped]:
    """Static transforms from `world_frame` to each (prefixed root frame, position [m], rpy [rad]); a root
    that is `world_frame` itself (an arm without a tf prefix whose URDF root is `world`) has none."""
    transforms = []
    for frame, position, rpy in roots:
        if frame == world_frame:
            continue
        tf = TransformStamped()
        tf.header.frame_id, tf.child_frame_id = world_frame, frame
        tf.transform.translation.x, tf.transform.translation.y, tf.transform.translation.z = position
        r = tf.transform.rotation
        r.w, r.x, r.y, r.z = (float(v) for v in rpy_to_quat(rpy))
        transforms.append(tf)
    return transforms


def build(arms: Sequence[tuple[str, tuple[float, float, float], tuple[float, float, float]]],
          viewer: bool, roots: list | None = None) -> MujocoDriverNode:
    """The node serving `arms` in one world.

    Raises:
        CellParamError, DriverParamError, ConfigError, SceneError: Naming the arm and the key.
    """
    use_sim_time = bool(rospy.get_param("/use_sim_time", False))
    found = []
    for name, position, rpy in arms:
        settings, urdf, tf = _arm(name, use_sim_time)
        try:
            scene = load_scene(settings)
        except (DriverParamError, ConfigError) as exc:
            raise CellParamError(f"arm {name}: {exc}") from None
        found.append((name, settings, urdf, tf, scene, CellArm(name, urdf, scene, position, rpy)))
        if roots is not None:
            roots.append((tf.add(urdf_root_link(urdf)), position, rpy))
    world = World([f[-1] for f in found])
    setups = [ArmSetup(settings, world.arms[name], scene, settings.base_frame or urdf_root_link(urdf),
                       PortNames(f"/{name}/{DRIVER_NAME}", f"/{name}"), tf)
              for name, settings, urdf, tf, scene, _ in found]
    first = found[0][1]
    wait = min(first.lockstep_wait, CELL_LOCKSTEP_WAIT)
    loop = dataclasses.replace(first, viewer=viewer, lockstep_wait=wait)
    return MujocoDriverNode(loop, world, setups)


def main(argv: list[str] | None = None) -> int:
    """Entry point of the ``mujoco_cell`` executable."""
    arms: list = []
    roots: list = []
    kept = []  # the broadcaster lives as long as the node

    def make() -> MujocoDriverNode:
        arms.extend(read_arms(rospy.get_param("~arms", None)))
        return build(arms, bool(rospy.get_param("~viewer", False)), roots)

    def started(_node: MujocoDriverNode) -> None:
        broadcaster = tf2_ros.StaticTransformBroadcaster()
        broadcaster.sendTransform(base_transforms(str(rospy.get_param("~world_frame", "world")), roots))
        kept.append(broadcaster)
        # A restarted roscore gets every arm's driver parameters and description back, as from its own driver.
        watch_master(["~", "/use_sim_time", *(f"/{name}/{key}" for name, _, _ in arms
                                              for key in (DRIVER_NAME, "robot_description"))])

    return serve("mujoco_cell", make, argv, started)
