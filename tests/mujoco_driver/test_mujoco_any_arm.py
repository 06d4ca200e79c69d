"""Arms the robot packages do not cover: continuous joints, COLLADA meshes, links without geometry.

A small Kinova-like arm is written here (base yaw, forearm roll and tool roll continuous); its links carry
a COLLADA cube written by hand, a broken COLLADA file, a flat mesh, or nothing. The Kinova Jaco2 of
example-robot-data (COLLADA meshes only, three continuous joints) is built at the end.
"""

from __future__ import annotations

import math
import pathlib
import sys
import xml.etree.ElementTree as ET

import mujoco
import numpy as np
import pytest
from control_stack.description import ToolSpec, build_description, find_example_robot_data, read_source
from mujoco_driver.meshes import LinkGeometry, prepare_collision
from mujoco_driver.scene import build_scene, mujoco_urdf_report
from mujoco_driver.sim import Simulation

from mujoco_driver.config import SceneConfig

# name, type, axis, origin in the parent link
_JOINTS = [
    ("yaw", "continuous", "0 0 1", "0 0 0.1"),
    ("shoulder", "revolute", "0 1 0", "0 0 0.1"),
    ("elbow", "revolute", "0 1 0", "0 0 0.4"),
    ("forearm_roll", "continuous", "1 0 0", "0.35 0 0"),
    ("wrist_pitch", "revolute", "0 1 0", "0.05 0 0"),
    ("tool_roll", "continuous", "1 0 0", "0.05 0 0"),
]
NAMES = [j[0] for j in _JOINTS]
SCENE = {
    "start_pose": [0.0, 0.0, 0.6, 0.0, 1.5, 0.0],
    "servo": {"kp": 300.0, "kv": 20.0, "armature": 0.05, "max_acceleration": 4.0},
    "table": {"center": [0.0, 0.0]},
}

# A cube of 10 x 20 x 30 units, centred, moved by (5, 0, 0) units in its node; 1 unit = 1 cm.
_CUBE_DAE = """<?xml version="1.0" encoding="utf-8"?>
<COLLADA xmlns="http://www.collada.org/2005/11/COLLADASchema" version="1.4.1">
  <asset><unit name="centimeter" meter="0.01"/><up_axis>Z_UP</up_axis></asset>
  <library_geometries>
    <geometry id="cube" name="cube"><mesh>
      <source id="cube-pos">
        <float_array id="cube-pos-array" count="24">{vertices}</float_array>
        <technique_common><accessor source="#cube-pos-array" count="8" stride="3">
          <param name="X" type="float"/><param name="Y" type="float"/><param name="Z" type="float"/>
        </accessor></technique_common>
      </source>
      <vertices id="cube-vtx"><input semantic="POSITION" source="#cube-pos"/></vertices>
      <triangles count="12"><input semantic="VERTEX" source="#cube-vtx" offset="0"/>
        <p>{faces}</p></triangles>
    </mesh></geometry>
  </library_geometries>
  <library_visual_scenes>
    <visual_scene id="scene"><node id="part" name="part"><translate>5 0 0</translate>
      <instance_geometry url="#cube"/></node></visual_scene>
  </library_visual_scenes>
  <scene><instance_visual_scene url="#scene"/></scene>
</COLLADA>
"""
_CUBE_VERTICES = [(x, y, z) for x in (-5, 5) for y in (-10, 10) for z in (-15, 15)]
# Outward-facing triangles of the cube above (vertex index = 4 x + 2 y + z with x, y, z in {0, 1}).
_CUBE_FACES = [
    (0, 1, 3), (0, 3, 2), (4, 6, 7), (4, 7, 5), (0, 4, 5), (0, 5, 1),
    (2, 3, 7), (2, 7, 6), (0, 2, 6), (0, 6, 4), (1, 5, 7), (1, 7, 3),
]
# Where the cube ends up in its link: collision origin (0.1, 0, 0) + node translation 5 cm.
CUBE_CENTRE = np.array([0.15, 0.0, 0.0])
CUBE_HALF = np.array([0.05, 0.1, 0.15])


def write_cube_dae(path: pathlib.Path) -> pathlib.Path:
    vertices = " ".join(f"{v}" for vertex in _CUBE_VERTICES for v in vertex)
    faces = " ".join(str(i) for face in _CUBE_FACES for i in face)
    path.write_text(_CUBE_DAE.format(vertices=vertices, faces=faces))
    return path


def write_flat_dae(path: pathlib.Path) -> pathlib.Path:
    """Two triangles in the z = 0 plane (a 4 x 2 cm sheet): trimesh reads it, MuJoCo could not use it."""
    text = _CUBE_DAE.replace('count="24"', 'count="12"').replace('count="8"', 'count="4"')
    text = text.replace('triangles count="12"', 'triangles count="2"')
    text = text.replace("<translate>5 0 0</translate>", "")
    path.write_text(text.format(vertices="-2 -1 0 2 -1 0 2 1 0 -2 1 0", faces="0 1 2 0 2 3"))
    return path


def _inertial(mass: float) -> str:
    return (f'<inertial><mass value="{mass}"/><origin xyz="0 0 0"/>'
            '<inertia ixx="0.004" iyy="0.004" izz="0.0005" ixy="0" ixz="0" iyz="0"/></inertial>')


def arm_urdf(geometry: dict[str, str]) -> str:
    """The test arm with a wrist tool; `geometry` maps link names (link1..link6) to their collision XML."""
    parts = ['<robot name="turner">', '<link name="base"/>']
    parent = "base"
    for i, (name, jtype, axis, xyz) in enumerate(_JOINTS):
        child = f"link{i + 1}"
        bounds = "" if jtype == "continuous" else 'lower="-2.8" upper="2.8"'
        parts += [
            f'<link name="{child}">{_inertial(1.0)}{geometry.get(child, "")}</link>',
            f'<joint name="{name}" type="{jtype}"><parent link="{parent}"/><child link="{child}"/>'
            f'<origin xyz="{xyz}" rpy="0 0 0"/><axis xyz="{axis}"/>'
            f'<limit effort="50" {bounds} velocity="2.0"/></joint>',
        ]
        parent = child
    parts += [
        '<link name="flange"/>',
        '<joint name="flange_joint" type="fixed"><parent link="link6"/><child link="flange"/>'
        '<origin xyz="0.05 0 0" rpy="0 1.5707963 0"/></joint>',
        "</robot>",
    ]
    return build_description("".join(parts), ToolSpec(parent="flange"))


def mesh_collision(path: pathlib.Path, xyz: str = "0 0 0", tag: str = "collision") -> str:
    return f'<{tag}><origin xyz="{xyz}" rpy="0 0 0"/><geometry><mesh filename="{path}"/></geometry></{tag}>'


def _body_vertices(model: mujoco.MjModel, data: mujoco.MjData, body: str) -> np.ndarray:
    """Vertices of every mesh geom of `body`, in the body's frame."""
    bid = model.body(body).id
    points = []
    for g in range(model.ngeom):
        if model.geom_bodyid[g] != bid or model.geom_type[g] != mujoco.mjtGeom.mjGEOM_MESH:
            continue
        m = model.geom_dataid[g]
        verts = model.mesh_vert[model.mesh_vertadr[m]:model.mesh_vertadr[m] + model.mesh_vertnum[m]]
        world = data.geom_xpos[g] + verts @ data.geom_xmat[g].reshape(3, 3).T
        points.append((world - data.xpos[bid]) @ data.xmat[bid].reshape(3, 3))
    return np.vstack(points) if points else np.zeros((0, 3))


def _geom_types(model: mujoco.MjModel, body: str) -> list[int]:
    bid = model.body(body).id
    return [int(model.geom_type[g]) for g in range(model.ngeom) if model.geom_bodyid[g] == bid]


@pytest.fixture
def cache(tmp_path: pathlib.Path) -> str:
    return str(tmp_path / "mesh_cache")


def test_collada_mesh_becomes_collision_geometry_in_metres(tmp_path: pathlib.Path, cache: str) -> None:
    dae = write_cube_dae(tmp_path / "cube.dae")
    urdf = arm_urdf({"link2": mesh_collision(dae, "0.1 0 0")})
    sim = Simulation(urdf, SCENE, mesh_cache=cache)
    report = {entry.link: entry for entry in sim.scene.geometry}
    assert report["link2"].action == "converted" and "cube.dae" in report["link2"].detail
    assert list(pathlib.Path(cache).glob("cube-*.stl")), "the STL goes to the cache directory"
    verts = _body_vertices(sim.model, sim.data, "link2")
    np.testing.assert_allclose(verts.min(axis=0), CUBE_CENTRE - CUBE_HALF, atol=1e-6)
    np.testing.assert_allclose(verts.max(axis=0), CUBE_CENTRE + CUBE_HALF, atol=1e-6)


def test_unreadable_meshes_and_missing_geometry_get_fitted_primitives(
    tmp_path: pathlib.Path, cache: str
) -> None:
    broken = tmp_path / "broken.dae"
    broken.write_text("<COLLADA>not a mesh")
    flat = write_flat_dae(tmp_path / "flat.dae")
    urdf = arm_urdf({
        "link3": mesh_collision(broken),  # unreadable: capsule to the child joint (0.35 m along x)
        "link4": mesh_collision(flat, "0 0 0.02"),  # flat: box over its bounds
        # link2 has mass and no geometry at all: capsule to its child joint (0.4 m along z)
    })
    sim = Simulation(urdf, SCENE, mesh_cache=cache)
    model, report = sim.model, {entry.link: entry for entry in sim.scene.geometry}
    capsule, box = int(mujoco.mjtGeom.mjGEOM_CAPSULE), int(mujoco.mjtGeom.mjGEOM_BOX)

    assert report["link2"].action == "capsule from child joints"
    assert "no geometry" in report["link2"].detail
    assert _geom_types(model, "link2") == [capsule]
    g = next(g for g in range(model.ngeom) if model.geom_bodyid[g] == model.body("link2").id)
    np.testing.assert_allclose(model.geom_pos[g], [0.0, 0.0, 0.2], atol=1e-9)  # from the joint to the child
    assert model.geom_size[g][1] == pytest.approx(0.2)  # half-length
    assert 0.01 <= model.geom_size[g][0] <= 0.1

    assert report["link3"].action == "capsule from child joints" and "broken.dae" in report["link3"].detail
    g = next(g for g in range(model.ngeom) if model.geom_bodyid[g] == model.body("link3").id)
    assert int(model.geom_type[g]) == capsule
    np.testing.assert_allclose(model.geom_pos[g], [0.175, 0.0, 0.0], atol=1e-9)

    assert report["link4"].action == "box from mesh bounds" and "flat" in report["link4"].detail
    g = next(g for g in range(model.ngeom) if model.geom_bodyid[g] == model.body("link4").id)
    assert int(model.geom_type[g]) == box
    np.testing.assert_allclose(model.geom_pos[g], [0.0, 0.0, 0.02], atol=1e-9)
    np.testing.assert_allclose(model.geom_size[g], [0.02, 0.01, 0.001], atol=1e-9)  # 2 mm thinnest side

    assert report["link1"].action == "capsule from child joints"  # 0.1 m to the shoulder
    assert report["flange"].action == "none" and report["tool"].action == "kept"
    sim.step(200)
    assert sim.warnings() == {}


def test_without_trimesh_the_fallback_is_said(
    tmp_path: pathlib.Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    dae = write_cube_dae(tmp_path / "cube.dae")
    monkeypatch.setitem(sys.modules, "trimesh", None)  # import trimesh -> ImportError
    two_meshes = mesh_collision(dae) + mesh_collision(dae, "0.1 0 0")
    urdf_text, report = mujoco_urdf_report(arm_urdf({"link3": two_meshes}), str(tmp_path / "c"))
    entry = next(e for e in report if e.link == "link3")
    assert entry.action == "capsule from child joints" and "trimesh is not installed" in str(entry)
    assert "cube.dae" not in urdf_text
    link3 = next(link for link in ET.fromstring(urdf_text).findall("link") if link.get("name") == "link3")
    assert len(link3.findall("collision/geometry/capsule")) == 1  # one capsule per child joint, not per mesh


def test_a_link_without_collision_takes_its_visual_mesh(tmp_path: pathlib.Path, cache: str) -> None:
    dae = write_cube_dae(tmp_path / "cube.dae")
    visual = mesh_collision(dae, "0.1 0 0", tag="visual")
    sim = Simulation(arm_urdf({"link2": visual}), SCENE, mesh_cache=cache)
    entry = next(e for e in sim.scene.geometry if e.link == "link2")
    assert entry.action == "from visual, converted"
    verts = _body_vertices(sim.model, sim.data, "link2")
    np.testing.assert_allclose(verts.max(axis=0), CUBE_CENTRE + CUBE_HALF, atol=1e-6)


def test_unresolved_visual_meshes_are_ignored(cache: str) -> None:
    visual = '<visual><geometry><mesh filename="package://elsewhere/meshes/link2.dae"/></geometry></visual>'
    urdf = arm_urdf({"link2": "VISUAL"}).replace("VISUAL", visual)  # make_description would refuse it
    sim = Simulation(urdf, SCENE, mesh_cache=cache)
    entry = next(e for e in sim.scene.geometry if e.link == "link2")
    assert entry.action == "capsule from child joints"


def test_converted_meshes_are_reused_from_the_cache(tmp_path: pathlib.Path, cache: str) -> None:
    dae = write_cube_dae(tmp_path / "cube.dae")
    urdf = arm_urdf({"link2": mesh_collision(dae)})
    first = prepare_collision(ET.fromstring(urdf), cache)
    stl = next(pathlib.Path(cache).glob("cube-*.stl"))
    stl.write_bytes(stl.read_bytes())  # same content, new mtime
    mtime = stl.stat().st_mtime_ns
    second = prepare_collision(ET.fromstring(urdf), cache)
    assert stl.stat().st_mtime_ns == mtime and first == second
    dae.write_text(dae.read_text().replace("<translate>5 0 0</translate>", ""))  # changed source: new file
    prepare_collision(ET.fromstring(urdf), cache)
    assert len(list(pathlib.Path(cache).glob("cube-*.stl"))) == 2
    assert isinstance(first[0], LinkGeometry)


def test_continuous_joints_are_unlimited_hinges_reported_as_one_unwrapped_angle(cache: str) -> None:
    sim = Simulation(arm_urdf({}), SCENE, mesh_cache=cache)
    model = sim.model
    for name, (_, jtype, _, _) in zip(NAMES, _JOINTS, strict=True):
        jid = model.joint(name).id
        assert model.jnt_type[jid] == mujoco.mjtJoint.mjJNT_HINGE
        assert bool(model.jnt_limited[jid]) == (jtype == "revolute"), name
    roll = sim.joint_names.index("tool_roll")
    assert sim.scene.lower[roll] == -math.inf and sim.scene.upper[roll] == math.inf
    velocity = np.zeros(6)
    velocity[roll] = 2.0  # the URDF limit
    sim.set_velocity_targets(velocity)
    sim.step(round(2.5 / sim.dt))  # 2.5 s: ~4.7 rad after the acceleration ramp
    assert sim.qpos.shape == (6,)  # what joint_states carries: one position per joint
    assert sim.qpos[roll] > 1.4 * math.pi, "unwrapped: past pi the angle keeps growing"
    assert sim.qvel[roll] == pytest.approx(2.0, rel=0.05)
    # A position command past pi is taken literally, the short way from where the joint is.
    target = sim.qpos.copy()
    target[roll] += 0.3
    sim.set_position_targets(target)
    sim.step(round(1.0 / sim.dt))
    assert sim.qpos[roll] == pytest.approx(target[roll], abs=0.01)
    assert sim.warnings() == {}


# --- the Kinova Jaco2 of example-robot-data ------------------------------------------------------------

KINOVA_HOME = [4.80, 2.92, 1.00, 4.19, 1.44, 1.31]


@pytest.fixture(scope="module")
def kinova(tmp_path_factory: pytest.TempPathFactory) -> tuple[str, Simulation]:
    erd = find_example_robot_data()
    stock = read_source("example-robot-data:robots/kinova_description/robots/kinova.urdf", erd)
    urdf = build_description(stock, ToolSpec(parent="j2s6s200_end_effector"), erd_dir=erd)
    cfg = SceneConfig.from_dict({
        "start_pose": KINOVA_HOME,
        "servo": {"kp": 200.0, "kv": 10.0, "armature": 0.05, "max_acceleration": 4.0},
    })
    return stock, Simulation(urdf, cfg, mesh_cache=str(tmp_path_factory.mktemp("kinova_meshes")))


def test_kinova_every_link_with_a_mesh_gets_mesh_geometry(kinova: tuple[str, Simulation]) -> None:
    stock, sim = kinova
    links = ET.fromstring(stock).findall("link")
    with_mesh = [link.get("name") for link in links if link.find(".//mesh") is not None]
    assert len(with_mesh) == 11  # base, 6 arm links, 4 finger links
    report = {entry.link: entry for entry in sim.scene.geometry}
    for name in with_mesh:
        assert report[name].action == "converted", report[name]
        assert int(mujoco.mjtGeom.mjGEOM_MESH) in _geom_types(sim.model, name), name
        assert len(_body_vertices(sim.model, sim.data, name)) > 100, name
    # The hand's mesh hangs below joint 6 along -z (URDF frame): the conversion kept the link frame.
    hand = _body_vertices(sim.model, sim.data, "j2s6s200_link_6")
    assert hand[:, 2].min() == pytest.approx(-0.1204, abs=2e-3) and hand[:, 2].max() < 0.01


def test_kinova_steps_without_warnings(kinova: tuple[str, Simulation]) -> None:
    _, sim = kinova
    sim.reset()
    assert [sim.model.jnt_limited[sim.model.joint(n).id] for n in sim.joint_names] == [0, 1, 1, 0, 1, 0]
    for _ in range(5):
        mujoco.mj_step(sim.model, sim.data)
    sim.step(250)
    assert sim.warnings() == {}
    np.testing.assert_allclose(sim.qpos, KINOVA_HOME, atol=0.01)


def test_build_scene_logs_each_changed_link(tmp_path: pathlib.Path, caplog: pytest.LogCaptureFixture) -> None:
    dae = write_cube_dae(tmp_path / "cube.dae")
    with caplog.at_level("INFO", logger="mujoco_driver.scene"):
        urdf = arm_urdf({"link2": mesh_collision(dae)})
        build_scene(urdf, SceneConfig.from_dict(SCENE), str(tmp_path / "c"))
    lines = [r.getMessage() for r in caplog.records]
    assert any(line.startswith("link link2: converted (cube.dae -> ") for line in lines), lines
    assert any(line.startswith("link link3: capsule from child joints") for line in lines), lines
    assert not any("link tool:" in line for line in lines)  # kept as given: not worth a line


def test_kinova_base_joint_turns_on_command(kinova: tuple[str, Simulation]) -> None:
    """Its first link touches the base (welded to the world) at their joint: that pair must not rub, or the
    continuous base joint stays put while the others move and a Cartesian jog drifts sideways."""
    _, sim = kinova
    sim.reset()
    sim.set_velocity_targets([0.1, 0.0, 0.0, 0.0, 0.0, 0.0])
    sim.step(750)  # 1.5 s at 0.1 rad/s after the 4 rad/s^2 ramp
    assert sim.qpos[0] - KINOVA_HOME[0] == pytest.approx(0.15, abs=0.02)
    sim.set_velocity_targets([0.0] * 6)
