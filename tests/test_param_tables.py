"""The parameter tables of the package READMEs are generated from the parameter declarations: regenerated
in memory here, a table that differs fails naming its package (fix: `make param-tables`)."""

from __future__ import annotations

import difflib
import pathlib
import re

import pytest
from compliant_common.schema_docs import MARKER, load_schema, render

SRC = pathlib.Path(__file__).resolve().parents[1] / "src"
READMES = sorted(SRC.glob("*/README.md"))
# Every node with private parameters has its table (the schema's module:attribute in the marker).
EXPECTED = {
    "contact_control": "contact_control.params:PARAMETERS",
    "jog_arm": "jog_arm.settings:PARAMETERS",
    "mujoco_driver": "mujoco_driver.params:PARAMETERS",
    "keyboard_publisher": "keyboard_publisher.teleop:PARAMETERS",
    "named_poses": "named_poses.params:PARAMETERS",
    "manipulator_control_gui": "manipulator_control_gui.params:PARAMETERS",
    "teach": "teach.params:PARAMETERS",
    "contact_tasks": "contact_tasks.params:PARAMETERS",
}


def _sources(readme: pathlib.Path) -> list[str]:
    return [m["source"] for m in MARKER.finditer(readme.read_text())]


@pytest.mark.parametrize("readme", READMES, ids=lambda p: p.parent.name)
def test_readme_parameter_tables_match_the_declarations(readme: pathlib.Path) -> None:
    text = readme.read_text()
    fresh = render(text)
    if fresh != text:
        old, new = text.splitlines(True), fresh.splitlines(True)
        diff = "".join(difflib.unified_diff(old, new, "README.md", "generated", n=0))
        pytest.fail(f"{readme.parent.name}: README parameter table out of date (`make param-tables`)\n{diff}")


@pytest.mark.parametrize(("package", "source"), sorted(EXPECTED.items()))
def test_every_node_with_parameters_has_a_generated_table(package: str, source: str) -> None:
    assert source in _sources(SRC / package / "README.md"), f"{package}: no params marker for {source}"
    assert len(load_schema(source)) > 0


def test_markers_are_paired_and_name_a_schema() -> None:
    for readme in READMES:
        text = readme.read_text()
        begins = len(re.findall(r"^<!-- params:begin ", text, re.M))
        ends = len(re.findall(r"^<!-- params:end -->$", text, re.M))
        assert begins == ends == len(_sources(readme)), f"{readme.parent.name}: unpaired params markers"
        for source in _sources(readme):
            load_schema(source)  # raises for a typo in the marker
