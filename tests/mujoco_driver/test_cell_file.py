"""Cell files (mujoco_driver README, *Cells*): what is refused and the launch file a cell makes."""

from __future__ import annotations

import xml.etree.ElementTree as ET

import pytest
import yaml
from mujoco_driver.cell_file import CellFileError, launch_xml, load_cell, parse_cell

GOOD = {"arms": [{"name": "left", "package": "ur5_custom"},
                 {"name": "right", "package": "panda_custom", "position": [0, 1.6, 0], "rpy": [0, 0, 1.57],
                  "args": {"fixture": "hand", "single_process": False}}]}

BIMANUAL = {"holder": "left", "presser": "right", "plate": [0.45, 0.3, 0.25], "press": [0.47, 0.47],
            "slide": [-0.04, 0.0]}


def test_the_shipped_cell_loads():
    import pathlib

    root = pathlib.Path(__file__).resolve().parents[2]
    cell = load_cell(str(root / "src/mujoco_driver/config/cells/ur5_panda.yaml"))
    assert [(a.name, a.package) for a in cell.arms] == [("left", "ur5_custom"), ("right", "panda_custom")]
    assert cell.arms[1].position == (0.0, 0.8, 0.0)
    assert cell.bimanual is not None and (cell.bimanual.holder, cell.bimanual.presser) == ("left", "right")


@pytest.mark.parametrize("data, words", [
    ({}, "expected the keys arms and (optional) bimanual"),
    ({**GOOD, "bimanual": {"holder": "left"}}, "bimanual: expected exactly the keys"),
    ({**GOOD, "bimanual": {**BIMANUAL, "holder": "middle"}}, "bimanual.holder: 'middle' is not an arm"),
    ({**GOOD, "bimanual": {**BIMANUAL, "presser": "left"}}, "the holder and the presser must be two arms"),
    ({**GOOD, "bimanual": {**BIMANUAL, "plate": [0.4, 0.3]}}, "bimanual.plate: expected three numbers"),
    ({**GOOD, "bimanual": {**BIMANUAL, "press": [0.4]}}, "bimanual.press: expected two numbers"),
    ({**GOOD, "bimanual": {**BIMANUAL, "slide": [0.2, 0.0]}}, "leaves the 0.5 m plate"),
    ({**GOOD, "bimanual": {**BIMANUAL, "press": [0.45, 0.35], "slide": [0.0, 0.0]}},
     "within 0.12 m of the plate's centre"),
    ({"arms": []}, "arms: expected a list"),
    ({"arms": [{"name": "left"}]}, "arms[0].package: expected a name"),
    ({"arms": [{"name": "le ft", "package": "ur5_custom"}]}, "arms[0].name: expected a name"),
    ({"arms": [{"name": "a", "package": "p", "pose": [0, 0, 0]}]}, "arms[0]: unknown keys ['pose']"),
    ({"arms": [{"name": "a", "package": "p", "args": ["fixture"]}]}, "arms[0].args: expected a mapping"),
    ({"arms": [{"name": "a", "package": "p", "args": {"ns": "b"}}]}, "arms[0].args: ['ns'] are the cell's"),
    ({"arms": [{"name": "a", "package": "p", "position": [0, 0]}]},
     "arms[0].position: expected three numbers"),
    ({"arms": [{"name": "a", "package": "p"}, {"name": "a", "package": "q"}]},
     "arms named ['a'] more than once"),
])
def test_a_bad_cell_is_refused_naming_the_key(data, words):
    with pytest.raises(CellFileError) as err:
        parse_cell(data, "c.yaml")
    assert words in str(err.value) and str(err.value).startswith("c.yaml")


def test_an_unreadable_file_is_refused_naming_it(tmp_path):
    with pytest.raises(CellFileError, match=r"missing\.yaml: cannot read"):
        load_cell(str(tmp_path / "missing.yaml"))


def test_the_launch_file_runs_each_arms_stack_in_its_namespace_without_a_driver_and_one_cell_node():
    root = ET.fromstring(launch_xml(parse_cell(GOOD), {"viewer": "true", "output": "log", "fixture": "none"}))
    includes = root.findall("include")
    assert [i.get("file") for i in includes] == ["$(find ur5_custom)/launch/sim.launch",
                                                 "$(find panda_custom)/launch/sim.launch"]
    args = [{a.get("name"): a.get("value") for a in include.findall("arg")} for include in includes]
    common = {"with_driver": "false", "output": "log", "fixture": "none"}
    assert args[0] == {**common, "ns": "left", "tf_prefix": "left"}
    assert args[1] == {**common, "ns": "right", "tf_prefix": "right", "fixture": "hand",
                       "single_process": "false"}
    node = root.find("node")
    assert node is not None and node.get("type") == "mujoco_cell" and node.get("output") == "log"
    arms = yaml.safe_load(node.find("rosparam").text)
    assert arms == [{"name": "left", "position": [0.0, 0.0, 0.0], "rpy": [0.0, 0.0, 0.0]},
                    {"name": "right", "position": [0.0, 1.6, 0.0], "rpy": [0.0, 0.0, 1.57]}]
    assert node.find("param").get("value") == "true"


def test_an_arms_own_argument_goes_to_that_arm_only_and_an_unknown_arm_is_refused():
    root = ET.fromstring(launch_xml(parse_cell(GOOD), {"left.tool": "plate", "right.fixture": "clear"}))
    args = [{a.get("name"): a.get("value") for a in i.findall("arg")} for i in root.findall("include")]
    assert args[0]["tool"] == "plate" and "tool" not in args[1]
    assert args[1]["fixture"] == "clear" and "fixture" not in args[0]  # over the cell file's own hand
    with pytest.raises(CellFileError, match=r"argument middle\.tool: no arm 'middle'"):
        launch_xml(parse_cell(GOOD), {"middle.tool": "plate"})


def test_the_cell_node_hangs_each_arms_tf_tree_from_the_world_at_its_base_pose():
    import math

    from mujoco_driver.cell_node import base_transforms

    left, right = base_transforms("world", [("left/world", (0.0, 0.0, 0.0), (0.0, 0.0, 0.0)),
                                            ("right/panda_link0", (0.0, 0.8, 0.1), (0.0, 0.0, math.pi / 2))])
    assert (left.header.frame_id, left.child_frame_id) == ("world", "left/world")
    t, q = right.transform.translation, right.transform.rotation
    assert (right.child_frame_id, (t.x, t.y, t.z)) == ("right/panda_link0", (0.0, 0.8, 0.1))
    assert (q.x, q.y, q.z, q.w) == pytest.approx((0.0, 0.0, math.sin(math.pi / 4), math.cos(math.pi / 4)))
    assert base_transforms("world", [("world", (0.0, 0.0, 0.0), (0.0, 0.0, 0.0))]) == []  # no loop


def test_apart_each_arm_runs_its_own_simulation_and_no_cell_node():
    root = ET.fromstring(launch_xml(parse_cell(GOOD), {"viewer": "true"}, one_world=False))
    assert root.find("node") is None
    for include in root.findall("include"):
        args = {a.get("name"): a.get("value") for a in include.findall("arg")}
        assert args["with_driver"] == "true" and args["viewer"] == "true"


@pytest.mark.parametrize("entries, words", [
    (None, "~arms: expected a list"),
    ([{"position": [0, 0, 0]}], "~arms[0]: expected a mapping with a name"),
    ([{"name": "a", "package": "p"}], "~arms[0]: unknown keys ['package']"),
    ([{"name": "a", "rpy": [0, "x", 0]}], "~arms[0].rpy: expected three numbers"),
])
def test_the_cell_nodes_arms_parameter_is_refused_naming_the_entry(entries, words):
    from mujoco_driver.cell_node import CellParamError, read_arms

    with pytest.raises(CellParamError) as err:
        read_arms(entries)
    assert words in str(err.value)


def test_the_cell_nodes_arms_parameter_gives_names_and_base_poses():
    from mujoco_driver.cell_node import read_arms

    assert read_arms([{"name": "/left/", "position": [0, 1, 0]}, {"name": "right", "rpy": [0, 0, 1]}]) == [
        ("left", (0.0, 1.0, 0.0), (0.0, 0.0, 0.0)), ("right", (0.0, 0.0, 0.0), (0.0, 0.0, 1.0))]
