"""Tool mass and centre of mass have one source, the robot description (config/description.args): every robot
package's contact_control configs must compensate exactly that tool. No description is built here (fast)."""

from __future__ import annotations

import pathlib
from typing import Any

import pytest
import yaml
from contact_control.params import ContactControlSettings
from control_stack.description import ToolSpec
from robot_setup.check import read_description_args, tool_payload_problems, tool_spec

SRC = pathlib.Path(__file__).resolve().parents[2] / "src"
ROBOT_PACKAGES = sorted(p.name for p in SRC.iterdir() if p.name.endswith("_custom"))


def _tool(package: str) -> ToolSpec:
    tool = tool_spec(read_description_args(str(SRC / package / "config" / "description.args")))
    assert tool is not None, f"{package}: description.args adds no tool"
    return tool


def _yaml(package: str, name: str) -> dict[str, Any]:
    return yaml.safe_load((SRC / package / "config" / name).read_text()) or {}


@pytest.mark.parametrize("package", ROBOT_PACKAGES)
def test_contact_control_compensates_the_tool_of_the_description(package: str) -> None:
    assert tool_payload_problems(_tool(package), _yaml(package, "contact_control.yaml")) == []


@pytest.mark.parametrize("package", ROBOT_PACKAGES)
def test_the_hardware_config_compensates_the_same_tool_or_leaves_it_to_the_driver(package: str) -> None:
    hardware = _yaml(package, "contact_control_hardware.yaml")
    if hardware.get("tool_mass", ContactControlSettings.tool_mass) == 0.0:
        # The vendor driver's wrench is already payload-compensated: the config says so (no default).
        assert "tool_mass" in hardware, f"{package}: contact_control_hardware.yaml does not set tool_mass"
        return
    assert tool_payload_problems(_tool(package), hardware, "contact_control_hardware.yaml") == []


def test_a_payload_that_differs_from_the_description_is_named() -> None:
    tool = _tool("ur5_custom")
    (mass,) = tool_payload_problems(tool, {"tool_mass": 1.5, "tool_com": [0.0, 0.0, 0.05]})
    assert mass == ("tool mass: description.args --tool-mass 1.0 kg, contact_control.yaml tool_mass 1.5 kg: "
                    "gravity compensation would leave 4.91 N")
    (com,) = tool_payload_problems(tool, {"tool_mass": 1.0, "tool_com": [0.0, 0.0, 0.08]}, "x.yaml")
    assert com == ("tool centre of mass: description.args --tool-com [0.0, 0.0, 0.05] m, x.yaml "
                   "tool_com [0.0, 0.0, 0.08] m")
    # Absent keys are contact_control's defaults: no payload at all.
    assert [p.split(":")[0] for p in tool_payload_problems(tool, {})] == ["tool mass", "tool centre of mass"]
