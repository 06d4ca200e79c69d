"""Cell files (mujoco_driver README, *Cells*): what is refused and the launch file a cell makes."""

from __future__ import annotations

import xml.etree.ElementTree as ET

import pytest
import yaml
from mujoco_driver.cell_file import CellFileError, launch_xml, load_cell, parse_cell

GOOD = {"arms": [{"name": "left", "package": "ur5_custom"},
                 {"name": "right", "package": "panda_custom", "position": [0, 1.6, 0], "rpy": [0, 0, 1.57],
                  "args": {"fixture": "hand", "single_process": False}}]}


def test_the_shipped_cell_loads():
    import pathlib

    root = pathlib.Path(__file__).resolve().parents[2]
    cell = load_cell(str(root / "src/mujoco_driver/config/cells/ur5_panda.yaml"))
    assert [(a.name, a.package) for a in cell.arms] == [("left", "ur5_custom"), ("right", "panda_custom")]
    assert cell.arms[1].position == (0.0, 1.6, 0.0)


@pytest.mark.parametrize("data, words", [
    ({}, "expected one key, arms"),
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
