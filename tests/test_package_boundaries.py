"""The packages' boundaries (read from source, no ROS master): no import cycle inside a package or between
packages, and rospy only in the adapters, so the logic under them stays testable without a master."""

from __future__ import annotations

import re
import textwrap

import pytest
from harness.imports import find_cycle, import_graph, imported_names, packages

# Modules that may import rospy: nodes, ROS I/O (ros_*, rospy_*), clients of the stack's interfaces and
# command lines, and service or action servers. Everything else is logic.
ADAPTER = re.compile(r"(node|.*_node|ros.*|.*client|cli|.*_cli|.*_server|.*_service)")
PACKAGES = packages()


def _logic_importing_rospy(root):
    """The modules under `root` that import rospy without an adapter's name."""
    return [str(path.relative_to(root)) for path in sorted(root.rglob("*.py"))
            if "rospy" in imported_names(path) and not ADAPTER.fullmatch(path.stem)]


def test_every_package_is_scanned():
    assert {"compliant_common", "contact_control", "jog_arm", "mujoco_driver", "teach", "thesis_demos",
            "robot_setup", "contact_tasks"} <= set(PACKAGES)


@pytest.mark.parametrize("package", sorted(PACKAGES))
def test_a_package_has_no_import_cycle(package):
    assert find_cycle(import_graph(PACKAGES[package])) is None


def test_the_packages_import_one_another_without_a_cycle():
    graph = {}
    for name, root in PACKAGES.items():
        used = set().union(*(imported_names(path) for path in root.rglob("*.py")))
        graph[name] = (used & set(PACKAGES)) - {name}
    # The scan sees the dependencies that are there: nodes on the shared runtime, teach on contact_control.
    assert "compliant_common" in graph["contact_control"] and "contact_control" in graph["teach"]
    assert find_cycle(graph) is None


@pytest.mark.parametrize("package", sorted(PACKAGES))
def test_only_adapters_import_rospy(package):
    logic = _logic_importing_rospy(PACKAGES[package])
    assert logic == [], f"{package}: rospy imported outside node, ros_*, *client, cli, *_server, *_service"


def test_the_thesis_demos_runner_and_its_teach_flow_share_a_client_instead_of_each_other():
    graph = import_graph(PACKAGES["thesis_demos"])
    assert "thesis_demos.stack_client" in graph["thesis_demos.teach_client"]
    assert "thesis_demos.runner" not in graph["thesis_demos.teach_client"]
    assert "thesis_demos.scenarios" not in graph["thesis_demos.geometry"]


def test_a_cycle_through_function_level_imports_is_found(tmp_path):
    """generate imports the templates inside `render`, the templates import generate inside theirs (and under
    TYPE_CHECKING): a cycle all the same."""
    package = tmp_path / "robot_setup"
    package.mkdir()
    (package / "__init__.py").write_text("")
    (package / "generate.py").write_text(textwrap.dedent("""\
        def command_line():
            return ""


        def render(plan):
            from robot_setup import templates

            return templates.render(plan)
    """))
    (package / "templates.py").write_text(textwrap.dedent("""\
        from typing import TYPE_CHECKING

        if TYPE_CHECKING:
            from robot_setup.generate import Plan


        def render(plan: Plan):
            from .generate import command_line

            return command_line()
    """))
    graph = import_graph(package)
    assert graph["robot_setup.templates"] == {"robot_setup.generate"}
    assert find_cycle(graph) == ["robot_setup.generate", "robot_setup.templates", "robot_setup.generate"]
    (package / "templates.py").write_text("def render(plan):\n    return ''\n")
    assert find_cycle(import_graph(package)) is None


def test_rospy_in_a_logic_module_is_found(tmp_path):
    package = tmp_path / "pkg"
    package.mkdir()
    (package / "__init__.py").write_text("")
    (package / "laws.py").write_text("def f():\n    import rospy.timer\n")
    (package / "ros_io.py").write_text("import rospy\n")
    assert _logic_importing_rospy(package) == ["laws.py"]
