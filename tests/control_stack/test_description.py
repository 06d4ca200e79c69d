"""make_description: the URDF every consumer reads (robot_state_publisher, Pinocchio, MuJoCo)."""

from __future__ import annotations

import os
import pathlib
import xml.etree.ElementTree as ET

import numpy as np
import pinocchio as pin
import pytest
from control_stack.description import (
    ERD_ENV,
    DescriptionError,
    ToolSpec,
    build_description,
    find_example_robot_data,
    read_source,
    resolve_package_uri,
)

UR5 = "example-robot-data:robots/ur_description/urdf/ur5_robot.urdf"
PANDA = "example-robot-data:robots/panda_description/urdf/panda.urdf"
TOOL_ARGS = ("--tool-parent", "tool0", "--tool-mass", "1.5", "--tool-com", "0", "0", "0.05")


def _links(urdf: str) -> set[str]:
    return {link.get("name") for link in ET.fromstring(urdf).findall("link")}


def test_executable_via_shebang_prints_urdf_with_sensor_and_tool(run_make_description):
    """Runs like roslaunch's command=: through its shebang, with whatever python3 is first on PATH."""
    result = run_make_description("--source", UR5, *TOOL_ARGS, python=None)
    assert result.returncode == 0, result.stderr
    robot = ET.fromstring(result.stdout)
    assert {"ft_sensor", "tool", "tool_tip", "tool0"} <= _links(result.stdout)
    meshes = [m.get("filename") for m in robot.iter("mesh")]
    assert meshes and all(m.startswith("file:///") for m in meshes)
    assert all(os.path.isfile(m[len("file://"):]) for m in meshes)


def test_tool_weight_and_frames_are_real_in_pinocchio(run_make_description):
    result = run_make_description("--source", UR5, *TOOL_ARGS, "--tool-size", "0.03", "0.12")
    model = pin.buildModelFromXML(result.stdout)
    data = model.createData()
    q = pin.neutral(model)
    pin.framesForwardKinematics(model, data, q)
    flange = data.oMf[model.getFrameId("tool0")]
    sensor = data.oMf[model.getFrameId("ft_sensor")]
    tip = data.oMf[model.getFrameId("tool_tip")]
    assert np.allclose(sensor.homogeneous, flange.homogeneous)
    assert np.allclose(sensor.actInv(tip.translation), [0, 0, 0.12])
    # The tool's mass sits at its centre of mass: mass-weighted centres differ by exactly 1.5 kg there.
    stock = pin.buildModelFromXML(read_source(UR5))
    com_tool, com_stock = pin.centerOfMass(model, data, q), pin.centerOfMass(stock, stock.createData(), q)
    total_tool, total_stock = pin.computeTotalMass(model), pin.computeTotalMass(stock)
    assert total_tool == pytest.approx(total_stock + 1.5)
    tool_com = sensor.act(np.array([0, 0, 0.05]))
    assert np.allclose(total_tool * com_tool - total_stock * com_stock, 1.5 * tool_com)


def test_remove_link_drops_subtree_and_its_joints(run_make_description):
    result = run_make_description(
        "--source", PANDA, "--remove-link", "panda_hand", "--tool-parent", "panda_link8"
    )
    assert result.returncode == 0, result.stderr
    links = _links(result.stdout)
    assert not links & {"panda_hand", "panda_leftfinger", "panda_rightfinger", "panda_hand_tcp"}
    model = pin.buildModelFromXML(result.stdout)
    assert list(model.names)[1:] == [f"panda_joint{i}" for i in range(1, 8)]


def test_args_file_with_comments(tmp_path: pathlib.Path, run_make_description):
    args = tmp_path / "robot.args"
    args.write_text(f"# a comment\n--source {UR5}\n--tool-parent tool0  # flange\n--tool-mass 2.0\n")
    result = run_make_description(f"@{args}")
    assert result.returncode == 0, result.stderr
    tool = next(link for link in ET.fromstring(result.stdout).findall("link") if link.get("name") == "tool")
    assert float(tool.find("inertial/mass").get("value")) == 2.0


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (("--source", "example-robot-data:robots/nope.urdf"), "not found"),
        (("--source", UR5, "--tool-parent", "no_such_link"), "no_such_link"),
        (("--source", UR5, "--remove-link", "no_such_link"), "no_such_link"),
        (("--source", UR5, "--tool-parent", "tool0", "--tool-mass", "0"), "mass"),
        (("--source", UR5, "--tool-parent", "tool0", "--tool-shape", "box", "--tool-size", "0.1"), "3 size"),
        (("--source", UR5, "--tool-parent", "tool0", "--tool-size", "0.03", "-0.1"), "positive"),
        (("--source", UR5, "--tool-parent", "tool0", "--tool-name", "tool0"), "already exist"),
    ],
)
def test_bad_arguments_fail_with_a_message_and_no_output(args, message, run_make_description):
    result = run_make_description(*args)
    assert result.returncode == 2
    assert result.stdout == ""
    assert message in result.stderr


def test_shapes_inertia():
    cyl = ToolSpec(parent="p", mass=2.0, shape="cylinder", size=(0.1, 0.3))
    side = 2 * (3 * 0.1**2 + 0.3**2) / 12
    assert cyl.principal_inertia() == pytest.approx((side, side, 2 * 0.1**2 / 2))
    box = ToolSpec(parent="p", mass=12.0, shape="box", size=(1.0, 2.0, 3.0))
    assert box.principal_inertia() == pytest.approx((13.0, 10.0, 5.0))
    assert box.length() == 3.0
    sphere = ToolSpec(parent="p", mass=1.0, shape="sphere", size=(0.5,))
    assert sphere.principal_inertia() == pytest.approx((0.1, 0.1, 0.1)) and sphere.length() == 1.0


def test_find_example_robot_data_walks_up_to_a_venv(tmp_path: pathlib.Path, monkeypatch: pytest.MonkeyPatch):
    share = tmp_path / ".venv/lib/python3.11/site-packages/cmeel.prefix/share/example-robot-data"
    (share / "robots").mkdir(parents=True)
    start = tmp_path / "src" / "pkg" / "scripts"
    start.mkdir(parents=True)
    monkeypatch.delenv(ERD_ENV, raising=False)
    assert find_example_robot_data(str(start)) == str(share)


def test_find_example_robot_data_env_var_first_and_clear_error(tmp_path, monkeypatch):
    (tmp_path / "robots").mkdir()
    monkeypatch.setenv(ERD_ENV, str(tmp_path))
    assert find_example_robot_data() == str(tmp_path)
    monkeypatch.setenv(ERD_ENV, str(tmp_path / "missing"))
    monkeypatch.setattr("control_stack.description._site_package_dirs", lambda: [])
    with pytest.raises(DescriptionError, match=ERD_ENV):
        find_example_robot_data(str(tmp_path))


def test_package_uris_resolve_through_ros_package_path(tmp_path, monkeypatch):
    pkg = tmp_path / "ws" / "my_robot"
    pkg.mkdir(parents=True)
    (pkg / "package.xml").write_text("<package/>")
    monkeypatch.setenv("ROS_PACKAGE_PATH", str(tmp_path / "ws"))
    assert resolve_package_uri("package://my_robot/m/a.stl", None) == f"file://{pkg}/m/a.stl"
    assert resolve_package_uri("file:///x.stl", None) == "file:///x.stl"
    with pytest.raises(DescriptionError, match="other_pkg"):
        resolve_package_uri("package://other_pkg/a.stl", None)


def test_build_description_rejects_non_urdf():
    with pytest.raises(DescriptionError, match="XML"):
        build_description("<robot")
    with pytest.raises(DescriptionError, match="<robot>"):
        build_description("<mujoco/>")


def test_a_rounded_tool_ends_in_a_ball_at_the_same_tip(run_make_description):
    """--tool-rounded: the cylinder's end becomes a hemisphere of its radius; the tip, mass and centre of mass
    stay (a ball-end tool for curved parts)."""
    result = run_make_description("--source", UR5, *TOOL_ARGS, "--tool-size", "0.03", "0.12",
                                  "--tool-rounded")
    assert result.returncode == 0, result.stderr
    tool = next(link for link in ET.fromstring(result.stdout).findall("link") if link.get("name") == "tool")
    shapes = {c.find("geometry")[0].tag: c.find("origin").get("xyz") for c in tool.findall("collision")}
    assert set(shapes) == {"cylinder", "sphere"}
    assert [float(v) for v in shapes["sphere"].split()] == pytest.approx([0.0, 0.0, 0.09])  # 0.12 - 0.03
    sphere = tool.find("collision/geometry/sphere")
    assert sphere is not None and float(sphere.get("radius")) == pytest.approx(0.03)
    model = pin.buildModelFromXML(result.stdout)
    data = model.createData()
    pin.framesForwardKinematics(model, data, pin.neutral(model))
    sensor, tip = data.oMf[model.getFrameId("ft_sensor")], data.oMf[model.getFrameId("tool_tip")]
    assert np.allclose(sensor.actInv(tip.translation), [0, 0, 0.12])  # the ball's bottom is the tip
    with pytest.raises(DescriptionError, match="rounded end needs a cylinder"):
        ToolSpec(parent="tool0", shape="box", size=(0.01, 0.01, 0.1), rounded=True).validate()


def test_a_plate_tool_hangs_a_square_plate_below_the_tip(run_make_description):
    """--tool-plate: a square plate hangs centred below the tool's end, its top face at the tip; the tip, mass
    and centre of mass stay (a bimanual cell's holder)."""
    result = run_make_description("--source", UR5, *TOOL_ARGS, "--tool-size", "0.03", "0.12",
                                  "--tool-plate", "0.36")
    assert result.returncode == 0, result.stderr
    tool = next(link for link in ET.fromstring(result.stdout).findall("link") if link.get("name") == "tool")
    boxes = [c for c in tool.findall("collision") if c.find("geometry")[0].tag == "box"]
    assert len(boxes) == 1 and len(tool.findall("visual")) == 2
    size = [float(v) for v in boxes[0].find("geometry/box").get("size").split()]
    centre = [float(v) for v in boxes[0].find("origin").get("xyz").split()]
    assert size == pytest.approx([0.36, 0.36, 0.01])
    assert centre == pytest.approx([0.0, 0.0, 0.125])  # its top face (0.12) is the tip
    assert float(tool.find("inertial/mass").get("value")) == pytest.approx(1.5)
    model = pin.buildModelFromXML(result.stdout)
    data = model.createData()
    pin.framesForwardKinematics(model, data, pin.neutral(model))
    sensor, tip = data.oMf[model.getFrameId("ft_sensor")], data.oMf[model.getFrameId("tool_tip")]
    assert np.allclose(sensor.actInv(tip.translation), [0, 0, 0.12])
    with pytest.raises(DescriptionError, match="plate width"):
        ToolSpec(parent="tool0", plate=-0.1).validate()
