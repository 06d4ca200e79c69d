"""Build the MuJoCo model of the scene from the URDF string and the scene settings.

The scene, all in the robot's base frame (the URDF root link, which is also MuJoCo's world frame):
  * the robot from the URDF: collision geometry only (visual meshes are dropped), every link a body
    (``fusestatic`` off) so the F/T sensor frame and the tool exist as bodies; meshes MuJoCo cannot read
    are converted or replaced by fitted primitives (``mujoco_driver.meshes``), continuous joints are
    unlimited hinges;
  * a table whose top is the z = 0 plane (the robot stands on it), a floor, an optional box obstacle;
  * a site at the F/T sensor frame carrying a MuJoCo ``force`` and ``torque`` sensor;
  * one PID joint servo per joint with inputs [position, velocity, feed-forward torque] (its I gain is
    zero: a PD servo with velocity and torque feed-forward), force-limited by the URDF ``effort``;
  * gravity compensation (``gravcomp``) on the arm's links but not on the sensor's subtree, so the
    servos track tightly while the sensor still carries the tool's weight.

MuJoCo's force/torque sensors report the interaction between the sensor body's subtree and its parent;
``mujoco_driver.sim`` turns that into the wrench the environment exerts on the tool.
"""

from __future__ import annotations

import logging
import math
import os
import xml.etree.ElementTree as ET
from collections.abc import Sequence
from dataclasses import dataclass, field

import mujoco
import numpy as np
from compliant_common.errors import StackError
from control_stack.description import DescriptionError, parse_robot

from mujoco_driver.config import Box, Hand, SceneConfig, Surface
from mujoco_driver.fixtures import hole_boxes
from mujoco_driver.meshes import LinkGeometry, prepare_collision

__all__ = [
    "ArmSpec", "SceneError", "SceneModel", "UrdfJoint", "arm_spec", "build_scene", "index_scene",
    "mujoco_urdf", "mujoco_urdf_report", "rpy_to_quat", "surface_top", "surface_truth", "urdf_joints",
]

_log = logging.getLogger(__name__)

_INPUT = mujoco.mjtCtrlInput
PID_INPUTS = int(_INPUT.mjINPUT_POS | _INPUT.mjINPUT_VEL | _INPUT.mjINPUT_FF)  # ctrl: [pos, vel, ff]
FT_SITE = "ft_sensor_site"
HAND_BODY, HAND_JOINT = "person_hand", "person_hand_slide"  # the hand fixture (config.Hand)
FORCE_SENSOR = "ft_force"
TORQUE_SENSOR = "ft_torque"
_INTEGRATORS = {
    "implicitfast": mujoco.mjtIntegrator.mjINT_IMPLICITFAST,
    "implicit": mujoco.mjtIntegrator.mjINT_IMPLICIT,
}


class SceneError(StackError):
    """Raised when the URDF and the scene settings cannot make a valid model."""


@dataclass(frozen=True)
class UrdfJoint:
    """Limits of a movable URDF joint (None where the URDF gives none)."""

    name: str
    type: str
    lower: float | None
    upper: float | None
    velocity: float | None
    effort: float | None


def rpy_to_quat(rpy: Sequence[float]) -> np.ndarray:
    """URDF roll-pitch-yaw (fixed axes X, Y, Z) to a MuJoCo quaternion (w, x, y, z)."""
    r, p, y = (v / 2.0 for v in rpy)
    cr, sr, cp, sp, cy, sy = math.cos(r), math.sin(r), math.cos(p), math.sin(p), math.cos(y), math.sin(y)
    return np.array([
        cr * cp * cy + sr * sp * sy,
        sr * cp * cy - cr * sp * sy,
        cr * sp * cy + sr * cp * sy,
        cr * cp * sy - sr * sp * cy,
    ])


def _parse(urdf_xml: str) -> ET.Element:
    try:
        return parse_robot(urdf_xml)
    except DescriptionError as exc:
        raise SceneError(str(exc)) from None


def urdf_joints(urdf_xml: str) -> dict[str, UrdfJoint]:
    """Movable joints of a URDF with their ``<limit>`` values, by name."""
    joints: dict[str, UrdfJoint] = {}
    for joint in _parse(urdf_xml).findall("joint"):
        jtype = joint.get("type", "")
        if jtype in ("fixed", "floating", "planar"):
            continue
        limit = joint.find("limit")

        def value(attr: str, limit: ET.Element | None = limit) -> float | None:
            text = limit.get(attr) if limit is not None else None
            return float(text) if text is not None else None

        lower, upper = value("lower"), value("upper")
        if jtype == "continuous":
            lower = upper = None
        joints[joint.get("name", "")] = UrdfJoint(
            joint.get("name", ""), jtype, lower, upper, value("velocity"), value("effort")
        )
    return joints


def mujoco_urdf(urdf_xml: str, mesh_cache: str | None = None) -> str:
    """The URDF as MuJoCo should read it: collision only, plain mesh paths, every link a body.

    Meshes MuJoCo cannot read are converted or replaced (see :func:`mujoco_urdf_report`).

    Raises:
        SceneError: On malformed XML or a mesh that is not a local file.
    """
    return mujoco_urdf_report(urdf_xml, mesh_cache)[0]


def mujoco_urdf_report(urdf_xml: str, mesh_cache: str | None = None) -> tuple[str, list[LinkGeometry]]:
    """:func:`mujoco_urdf` and what became of each link's collision geometry.

    Collision meshes MuJoCo cannot read (COLLADA, ...) are converted to STL in `mesh_cache`
    (default :func:`mujoco_driver.meshes.default_cache_dir`) or replaced by fitted primitives; a link
    without collision geometry takes its visual one, or a capsule to its child joints if it has mass.

    Raises:
        SceneError: On malformed XML or a mesh that is not a local file.
    """
    robot = _parse(urdf_xml)
    for link in robot.findall("link"):
        # Visual meshes only matter as stand-ins for a missing collision: unusable ones go, unchecked.
        for visual in link.findall("visual"):
            for mesh in visual.iter("mesh"):
                path = _local_path(mesh.get("filename", ""))
                if path is None or not os.path.isfile(path):
                    link.remove(visual)
                    break
                mesh.set("filename", path)
        for mesh in (m for collision in link.findall("collision") for m in collision.iter("mesh")):
            uri = mesh.get("filename", "")
            path = _local_path(uri)
            if path is None:
                raise SceneError(
                    f"collision mesh {uri!r} is not an absolute path; resolve it (make_description)"
                )
            if not os.path.isfile(path):
                raise SceneError(f"collision mesh {path} does not exist")
            mesh.set("filename", path)
    for link in robot.findall("link"):
        _sane_inertia(link)
    report = prepare_collision(robot, mesh_cache)
    for link in robot.findall("link"):
        for visual in link.findall("visual"):
            link.remove(visual)
    for old in robot.findall("mujoco"):
        robot.remove(old)
    extension = ET.SubElement(robot, "mujoco")
    ET.SubElement(extension, "compiler", fusestatic="false", discardvisual="true", strippath="false",
                  balanceinertia="true")
    return ET.tostring(robot, encoding="unicode"), report


def _sane_inertia(link: ET.Element) -> None:
    """A link whose inertia matrix is not positive definite (TIAGo's antenna links: products larger than the
    moments) keeps only its moments: MuJoCo refuses to compile such a body; for a link that light or small the
    difference does not matter."""
    inertia = link.find("inertial/inertia")
    if inertia is None:
        return
    try:
        v = {k: float(inertia.get(k, "0")) for k in ("ixx", "ixy", "ixz", "iyy", "iyz", "izz")}
    except ValueError:
        return
    matrix = np.array([[v["ixx"], v["ixy"], v["ixz"]], [v["ixy"], v["iyy"], v["iyz"]],
                       [v["ixz"], v["iyz"], v["izz"]]])
    if np.all(np.linalg.eigvalsh(matrix) > 0.0):
        return
    _log.info("link %s: inertia not positive definite, its products of inertia dropped", link.get("name"))
    for key in ("ixy", "ixz", "iyz"):
        inertia.set(key, "0")
    for key in ("ixx", "iyy", "izz"):
        inertia.set(key, repr(max(abs(v[key]), 1e-9)))


def _local_path(uri: str) -> str | None:
    """The absolute file path of a mesh URI (plain or ``file://``), None for anything else."""
    path = uri[len("file://"):] if uri.startswith("file://") else uri
    return path if "://" not in path and os.path.isabs(path) else None


@dataclass
class SceneModel:
    """The compiled model and the indices the simulation core needs.

    Attributes:
        model: The compiled MjModel.
        joint_names: Movable joints, in model (and URDF tree) order.
        arm_index: Positions in `joint_names` of the arm's joints (all but the held ones), in that order.
        qpos_adr: qpos address of each joint.
        dof_adr: qvel address of each joint.
        ctrl_adr: ctrl address of each joint's servo: [adr] position, [adr+1] velocity, [adr+2] torque.
        lower: Lower position limits [rad or m] (-inf when unlimited).
        upper: Upper position limits.
        velocity_limit: Velocity limits from the URDF [rad/s or m/s] (inf when absent).
        max_acceleration: Setpoint acceleration limits from the scene settings [rad/s^2 or m/s^2].
        max_deceleration: Their limits while slowing down (config.ServoConfig).
        start_pose: Start joint positions.
        ft_site: Site id at the F/T sensor frame.
        force_adr: sensordata address of the force sensor (3 values).
        torque_adr: sensordata address of the torque sensor (3 values).
        sensor_body: Body id of the F/T sensor frame link (root of the measured subtree).
        tool_body: Body id of the tool link (pushes are applied at its centre of mass).
        eef_body: Body id of the end-effector frame link.
        payload_mass: Mass below the sensor [kg].
        geometry: What became of each link's collision geometry (kept, converted, fitted primitive, none).
        prefix: The arm's name prefix in a world of several arms (mujoco_driver.cell); '' alone.
    """

    model: mujoco.MjModel
    joint_names: list[str]
    arm_index: np.ndarray
    qpos_adr: np.ndarray
    dof_adr: np.ndarray
    ctrl_adr: np.ndarray
    lower: np.ndarray
    upper: np.ndarray
    velocity_limit: np.ndarray
    max_acceleration: np.ndarray
    max_deceleration: np.ndarray
    start_pose: np.ndarray
    ft_site: int
    force_adr: int
    torque_adr: int
    sensor_body: int
    tool_body: int
    eef_body: int
    payload_mass: float
    geometry: list[LinkGeometry] = field(default_factory=list)
    prefix: str = ""


def _subtree(root: mujoco.MjsBody) -> list[mujoco.MjsBody]:
    bodies, stack = [], [root]
    while stack:
        body = stack.pop()
        bodies.append(body)
        stack.extend(body.bodies)
    return bodies


# The block's contact impedance (MuJoCo solimp: dmin, dmax, width [m], midpoint, power). With MuJoCo's default
# (0.9, 0.95, 0.001) a flat tool face sliding over the block's top at 10 N hopped at ~70 Hz: its contacts
# vanished every 7 steps and the force fell to 2.6 N for one step (raw std 2.8 N), which a 125 Hz driver's
# samples alias into 6-12 N means. Starting softer (0.5) over 5 mm keeps the tool in contact while it slides
# (std 0.05-0.2 N) and still makes a stiff block: ~150 N/mm at the tool tip, 0.2 mm deep at 20 N (README).
OBSTACLE_SOLIMP = [0.5, 0.95, 0.005, 0.5, 2.0]


def _add_environment(spec: mujoco.MjSpec, cfg: SceneConfig) -> None:
    world, table = spec.worldbody, cfg.table
    world.add_light(name="sun", pos=[0.0, 0.0, 3.0], dir=[0.0, 0.0, -1.0])
    world.add_geom(name="floor", type=mujoco.mjtGeom.mjGEOM_PLANE, size=[3.0, 3.0, 0.1],
                   pos=[0.0, 0.0, -table.height], rgba=[0.5, 0.5, 0.5, 1.0])
    world.add_geom(name="table", type=mujoco.mjtGeom.mjGEOM_BOX,
                   size=[table.size[0] / 2, table.size[1] / 2, table.thickness / 2],
                   pos=[table.center[0], table.center[1], -table.thickness / 2], rgba=[0.6, 0.45, 0.3, 1.0])
    if cfg.obstacle is not None:
        obs, surface = cfg.obstacle, cfg.surface
        if surface is not None and surface.kind != "plane":
            geom = _add_curved(world, obs, surface)
        else:
            geom = world.add_geom(name="obstacle", type=mujoco.mjtGeom.mjGEOM_BOX,
                                  size=[s / 2 for s in obs.size], pos=list(obs.position),
                                  quat=rpy_to_quat(obs.rpy), rgba=[0.8, 0.2, 0.2, 1.0])
        geom.solimp = OBSTACLE_SOLIMP
        if surface is not None:  # its friction, not the tool's, makes the contact's
            geom.priority, geom.friction = 1, [surface.friction, 0.005, 0.0001]
        if cfg.hole is not None:
            for box in hole_boxes(obs, cfg.hole):
                part = world.add_geom(name=box.name, type=mujoco.mjtGeom.mjGEOM_BOX, size=list(box.half),
                                      pos=list(box.pos), quat=list(box.quat), rgba=[0.7, 0.7, 0.75, 1.0])
                part.solimp = OBSTACLE_SOLIMP
        if cfg.hand is not None and not cfg.hand.free:
            _add_hand(spec, obs, cfg.hand)
    if cfg.hand is not None and cfg.hand.free:
        _add_free_hand(spec, cfg.hand)


def _add_curved(world: mujoco.MjsBody, block: Box, surface: Surface) -> mujoco.MjsGeom:
    """The cylinder (axis along y, as long as the block is wide) or sphere in the block's place, its top at
    the block's top centre moved by the surface's offset (config.Surface)."""
    top = surface_top(block, surface)
    centre = [top[0], top[1], top[2] - surface.radius]
    if surface.kind == "cylinder":
        return world.add_geom(name="obstacle", type=mujoco.mjtGeom.mjGEOM_CYLINDER,
                              size=[surface.radius, block.size[1] / 2.0, 0.0], pos=centre,
                              quat=[math.sqrt(0.5), math.sqrt(0.5), 0.0, 0.0], rgba=[0.8, 0.2, 0.2, 1.0])
    return world.add_geom(name="obstacle", type=mujoco.mjtGeom.mjGEOM_SPHERE, size=[surface.radius, 0.0, 0.0],
                          pos=centre, rgba=[0.8, 0.2, 0.2, 1.0])


def surface_truth(block: Box, surface: Surface) -> dict[str, object]:
    """Where the finishing fixture truly is (the driver's `~surface`, for plots and tests): its kind, radius
    [m], top [m] (a curved part's highest point; the tilted block's top face centre), for the tilted block
    its rpy [rad], and its friction with the tool."""
    if surface.kind == "plane":
        R = np.zeros(9)
        mujoco.mju_quat2Mat(R, rpy_to_quat(block.rpy))
        top = np.asarray(block.position) + R.reshape(3, 3)[:, 2] * block.size[2] / 2.0
        return {"kind": "tilted", "radius": 0.0, "top": [float(x) for x in top], "rpy": list(block.rpy),
                "friction": surface.friction}
    return {"kind": surface.kind, "radius": surface.radius, "top": list(surface_top(block, surface)),
            "rpy": [0.0, 0.0, 0.0], "friction": surface.friction}


def surface_top(block: Box, surface: Surface) -> tuple[float, float, float]:
    """The curved part's highest point [m], where the block's top centre is without an offset."""
    dx, dy, dz = surface.offset
    x, y, z = block.position
    return x + dx, y + dy, z + block.size[2] / 2.0 + dz


def _add_hand(spec: mujoco.MjSpec, block: Box, hand: Hand) -> None:
    """The hand on the block's top centre (config.Hand): its spring holds it there, weightless (gravcomp)."""
    top = block.position[2] + block.size[2] / 2.0
    body = spec.worldbody.add_body(name=HAND_BODY, pos=[block.position[0], block.position[1],
                                                        top + hand.size[2] / 2.0])
    body.gravcomp = 1.0
    body.add_joint(name=HAND_JOINT, type=mujoco.mjtJoint.mjJNT_SLIDE, axis=[0.0, 0.0, 1.0],
                   stiffness=hand.stiffness, springref=0.0, range=[-hand.travel, 0.05],
                   limited=mujoco.mjtLimited.mjLIMITED_TRUE,
                   damping=2.0 * hand.damping_ratio * math.sqrt(hand.stiffness * hand.mass))
    body.add_geom(name=HAND_BODY, type=mujoco.mjtGeom.mjGEOM_BOX, size=[a / 2.0 for a in hand.size],
                  mass=hand.mass, rgba=[0.9, 0.7, 0.55, 1.0])
    spec.add_exclude(bodyname1="world", bodyname2=HAND_BODY)  # it sinks into the block as it is pressed


def _add_free_hand(spec: mujoco.MjSpec, hand: Hand) -> None:
    """The hand held in the air (config.Hand, `free`), weightless (gravcomp)."""
    x, y, z = hand.at
    body = spec.worldbody.add_body(name=HAND_BODY, pos=[x, y, z + hand.size[2] / 2.0])
    body.gravcomp = 1.0
    body.add_joint(name=HAND_JOINT, type=mujoco.mjtJoint.mjJNT_SLIDE, axis=[0.0, 0.0, 1.0],
                   stiffness=hand.hold_stiffness, springref=0.0, range=[-hand.reach, 0.05],
                   limited=mujoco.mjtLimited.mjLIMITED_TRUE,
                   damping=2.0 * math.sqrt(hand.hold_stiffness * hand.mass))
    geom = body.add_geom(name=HAND_BODY, type=mujoco.mjtGeom.mjGEOM_BOX, size=[a / 2.0 for a in hand.size],
                         mass=hand.mass, rgba=[0.9, 0.7, 0.55, 1.0])
    # The tissue is the contact: MuJoCo's direct solref is a reference acceleration per metre of penetration
    # (and per m/s), k / m_H the hand's own, so the contact is k against a tool much heavier than the hand.
    omega2 = hand.stiffness / hand.mass
    geom.solref = [-omega2, -2.0 * hand.damping_ratio * math.sqrt(omega2)]
    geom.solimp = [0.99, 0.99, 0.001, 0.5, 2.0]
    geom.priority = 2  # its solref and solimp make the contact's
    spec.add_exclude(bodyname1="world", bodyname2=HAND_BODY)


OVERLAP_SAMPLES = 8  # postures (the start pose and fixed pseudo-random ones) a pair must touch in all of


def _overlapping_links(
    model: mujoco.MjModel, names: Sequence[str], arm_names: Sequence[str], start: np.ndarray,
    measured: set[str],
) -> list[tuple[str, str]]:
    """Pairs of the robot's links (not the tool's) that penetrate in every one of OVERLAP_SAMPLES postures
    of the arm: a link's mesh reaching into its mount or a neighbour (TIAGo's first arm link in its torso
    column, its wrist links), which MuJoCo would push apart from the first step."""
    data = mujoco.MjData(model)
    adr = {n: int(model.jnt_qposadr[model.joint(n).id]) for n in names}
    for name, value in zip(names, start, strict=True):
        data.qpos[adr[name]] = value
    rng = np.random.default_rng(0)
    always: set[tuple[int, int]] | None = None
    for k in range(OVERLAP_SAMPLES):
        if k:
            for name in arm_names:
                jid = model.joint(name).id
                lo, hi = model.jnt_range[jid] if model.jnt_limited[jid] else (-math.pi, math.pi)
                data.qpos[adr[name]] = lo + (hi - lo) * rng.random()
        mujoco.mj_kinematics(model, data)
        mujoco.mj_collision(model, data)
        pairs = set()
        for i in range(data.ncon):
            con = data.contact[i]
            a, b = sorted((int(model.geom_bodyid[con.geom1]), int(model.geom_bodyid[con.geom2])))
            if con.dist < 0.0 and a > 0:  # body 0 (world): the table, floor and obstacle
                pairs.add((a, b))
        always = pairs if always is None else always & pairs
        if not always:
            return []
    body = lambda i: mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_BODY, i)  # noqa: E731
    return sorted((body(a), body(b)) for a, b in always or set() if not {body(a), body(b)} & measured)


@dataclass
class ArmSpec:
    """One arm's scene before it is placed in a world: the spec (compiled once, checked) and what indexing
    its compiled model needs (:func:`index_scene`)."""

    spec: mujoco.MjSpec
    model: mujoco.MjModel
    cfg: SceneConfig
    names: list[str]
    arm_names: list[str]
    start: np.ndarray
    max_acceleration: np.ndarray
    max_deceleration: np.ndarray
    velocity: list[float | None]
    geometry: list[LinkGeometry]


def build_scene(urdf_xml: str, cfg: SceneConfig, mesh_cache: str | None = None) -> SceneModel:
    """Compile the scene.

    Continuous URDF joints become unlimited hinges (MuJoCo's URDF reader does that; their range is
    -inf..inf here). Links whose geometry had to be converted or replaced are logged (INFO) and listed
    in :attr:`SceneModel.geometry`.

    Args:
        urdf_xml: The robot description (meshes as absolute paths or ``file://`` URIs).
        cfg: The validated scene settings.
        mesh_cache: Directory of converted meshes; None = :func:`mujoco_driver.meshes.default_cache_dir`.

    Returns:
        The compiled model with its indices.

    Raises:
        SceneError: If MuJoCo rejects the URDF, a named link is missing, a joint is not a 1-DoF hinge or
            slide, or a per-joint setting does not match the URDF's joints.
    """
    arm = arm_spec(urdf_xml, cfg, mesh_cache)
    return index_scene(arm.model, arm)


def arm_spec(urdf_xml: str, cfg: SceneConfig, mesh_cache: str | None = None) -> ArmSpec:
    """The arm's scene (:func:`build_scene`), compiled alone and checked, ready to be placed in a world.

    Raises:
        SceneError: As :func:`build_scene`.
    """
    limits = urdf_joints(urdf_xml)
    mjcf_urdf, geometry = mujoco_urdf_report(urdf_xml, mesh_cache)
    for entry in geometry:
        if entry.changed:
            _log.info("%s", entry)
    try:
        spec = mujoco.MjSpec.from_string(mjcf_urdf)
    except ValueError as exc:
        raise SceneError(f"MuJoCo cannot read the URDF: {exc}") from exc
    spec.option.timestep = cfg.timestep
    spec.option.integrator = _INTEGRATORS[cfg.integrator]

    bodies = {body.name: body for body in spec.bodies}
    for role in ("ft_sensor", "tool", "eef"):
        name = getattr(cfg.links, role)
        if name not in bodies:
            raise SceneError(f"links.{role}: link {name!r} not in the URDF (did make_description add it?)")
    sensor_body = bodies[cfg.links.ft_sensor]
    measured = {b.name for b in _subtree(sensor_body)}
    if cfg.links.tool not in measured:
        raise SceneError(f"links.tool {cfg.links.tool!r} not below links.ft_sensor {cfg.links.ft_sensor!r}.")

    joints = [j for j in spec.joints]
    names = [j.name for j in joints]
    unknown = [n for n in cfg.held_joints if n not in names]
    if unknown:
        raise SceneError(f"held_joints: {unknown} are not movable joints of the URDF {names}")
    arm_names = [n for n in names if n not in cfg.held_joints]
    for joint in joints:
        if joint.type not in (mujoco.mjtJoint.mjJNT_HINGE, mujoco.mjtJoint.mjJNT_SLIDE):
            raise SceneError(f"joint {joint.name}: only revolute/prismatic joints are supported")
        if joint.name in measured:
            raise SceneError(f"joint {joint.name} is below the F/T sensor; the sensor needs a rigid tool")
    try:
        kp = cfg.servo.kp.resolve(names)
        kv = cfg.servo.kv.resolve(names)
        armature = cfg.servo.armature.resolve(names)
        arm_start = dict(zip(arm_names, cfg.start_pose.resolve(arm_names), strict=True))
        start = np.array([arm_start[n] if n in arm_start else cfg.held_joints[n] for n in names])
        max_acceleration = np.array(cfg.servo.max_acceleration.resolve(names))
        braking = cfg.servo.max_deceleration
        max_deceleration = max_acceleration if braking is None else np.array(braking.resolve(names))
    except ValueError as exc:
        held = (f" (held joints: {sorted(cfg.held_joints)})" if cfg.held_joints else
                " (joints outside the arm go in held_joints: name -> position)")
        raise SceneError(f"{exc}{held}") from exc

    for body in spec.bodies:
        if body.name != "world":
            body.gravcomp = 0.0 if body.name in measured else 1.0
    for joint, gain_p, gain_v, arm in zip(joints, kp, kv, armature, strict=True):
        joint.armature = arm
        act = spec.add_actuator(
            name=f"{joint.name}_servo", target=joint.name, trntype=mujoco.mjtTrn.mjTRN_JOINT
        )
        act.set_to_pid(kp=gain_p, kv=gain_v, ctrlspec=PID_INPUTS)
    site = sensor_body.add_site(name=FT_SITE, size=[0.01, 0.0, 0.0])
    for sensor_name, sensor_type in ((FORCE_SENSOR, mujoco.mjtSensor.mjSENS_FORCE),
                                     (TORQUE_SENSOR, mujoco.mjtSensor.mjSENS_TORQUE)):
        spec.add_sensor(
            name=sensor_name, type=sensor_type, objtype=mujoco.mjtObj.mjOBJ_SITE, objname=site.name
        )
    # A link and its parent touch at their joint by design; MuJoCo only filters such pairs when the parent
    # moves, so a first link turning on a base welded to the world would rub it (seen freezing the Jaco2's
    # continuous base joint). Exclude every parent-child pair explicitly.
    for body in spec.bodies:
        parent = body.parent
        if body.name != "world" and parent is not None and parent.name != "world":
            spec.add_exclude(bodyname1=parent.name, bodyname2=body.name)
    _add_environment(spec, cfg)
    try:
        model = spec.compile()
        overlaps = _overlapping_links(model, names, arm_names, start, measured)
        if overlaps:  # meshes that overlap by design would push the arm from its start: not contacts
            _log.info("links whose meshes overlap in every posture, not collided: %s",
                      ", ".join(f"{a} / {b}" for a, b in overlaps))
            for a, b in overlaps:
                spec.add_exclude(bodyname1=a, bodyname2=b)
            model = spec.compile()
    except ValueError as exc:
        raise SceneError(f"MuJoCo cannot compile the scene: {exc}") from exc
    vel = [limits[n].velocity if n in limits and limits[n].velocity else np.inf for n in names]
    return ArmSpec(spec, model, cfg, names, arm_names, start, max_acceleration, max_deceleration, vel,
                   geometry)


def index_scene(model: mujoco.MjModel, arm: ArmSpec, prefix: str = "") -> SceneModel:
    """The indices of `arm` in `model`: its own compiled model, or a world it was attached to with `prefix`
    on its names (mujoco_driver.cell).

    Raises:
        SceneError: If the start pose is outside the joints' limits.
    """
    cfg, names = arm.cfg, arm.names
    jids = [model.joint(prefix + n).id for n in names]
    lower = np.array([model.jnt_range[j, 0] if model.jnt_limited[j] else -np.inf for j in jids])
    upper = np.array([model.jnt_range[j, 1] if model.jnt_limited[j] else np.inf for j in jids])
    outside = [n for n, q, lo, hi in zip(names, arm.start, lower, upper, strict=True) if not lo <= q <= hi]
    if outside:
        raise SceneError(f"start_pose / held_joints: joints {outside} outside their limits")
    sensor_id = model.body(prefix + cfg.links.ft_sensor).id
    return SceneModel(
        model=model,
        joint_names=list(names),
        arm_index=np.array([names.index(n) for n in arm.arm_names], dtype=np.intp),
        qpos_adr=np.array([model.jnt_qposadr[j] for j in jids]),
        dof_adr=np.array([model.jnt_dofadr[j] for j in jids]),
        ctrl_adr=np.array([model.actuator_ctrladr[model.actuator(f"{prefix}{n}_servo").id] for n in names]),
        lower=lower,
        upper=upper,
        velocity_limit=np.array(arm.velocity, dtype=float),
        max_acceleration=arm.max_acceleration,
        max_deceleration=arm.max_deceleration,
        start_pose=arm.start,
        ft_site=model.site(prefix + FT_SITE).id,
        force_adr=int(model.sensor_adr[model.sensor(prefix + FORCE_SENSOR).id]),
        torque_adr=int(model.sensor_adr[model.sensor(prefix + TORQUE_SENSOR).id]),
        sensor_body=sensor_id,
        tool_body=model.body(prefix + cfg.links.tool).id,
        eef_body=model.body(prefix + cfg.links.eef).id,
        payload_mass=float(model.body_subtreemass[sensor_id]),
        geometry=arm.geometry,
        prefix=prefix,
    )
