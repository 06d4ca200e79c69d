"""robot_setup's modules import one another without a cycle. Every import counts, at module level, inside a
function or under TYPE_CHECKING: an import moved into a function still ties the two modules together (the
templates once imported `generate` inside `render`, and `generate` imported the templates). No ROS master."""

from __future__ import annotations

import ast
import pathlib
import textwrap

ROBOT_SETUP = pathlib.Path(__file__).resolve().parents[2] / "src" / "robot_setup" / "src" / "robot_setup"


def _modules(root: pathlib.Path) -> dict[str, pathlib.Path]:
    """Dotted module name -> file, for the package at `root` (a package is its __init__.py)."""
    modules = {}
    for path in sorted(root.rglob("*.py")):
        parts = (root.name, *path.relative_to(root).with_suffix("").parts)
        if parts[-1] == "__init__":
            parts = parts[:-1]
        modules[".".join(parts)] = path
    return modules


def _imported(node: ast.Import | ast.ImportFrom, module: str, is_package: bool) -> list[str]:
    """The dotted names an import statement can load: `from a import b` loads a.b if b is a module."""
    if isinstance(node, ast.Import):
        return [alias.name for alias in node.names]
    base = node.module or ""
    if node.level:  # relative: from the module's package, up level - 1 more
        package = module.split(".") if is_package else module.split(".")[:-1]
        anchor = ".".join(package[: len(package) - (node.level - 1)])
        base = f"{anchor}.{base}" if base else anchor
    return [base] + [f"{base}.{alias.name}" for alias in node.names]


def import_graph(root: pathlib.Path) -> dict[str, set[str]]:
    """Module -> the package's modules it imports (the named module only, not its parent packages: those
    are already being imported when a submodule imports its sibling)."""
    modules = _modules(root)
    graph: dict[str, set[str]] = {}
    for module, path in modules.items():
        targets = set()
        for node in ast.walk(ast.parse(path.read_text(), str(path))):
            if isinstance(node, ast.Import | ast.ImportFrom):
                for name in _imported(node, module, path.name == "__init__.py"):
                    # The longest prefix that is one of the package's modules (`import a.b.c` loads a.b.c).
                    parts = name.split(".")
                    found = next((".".join(parts[:n]) for n in range(len(parts), 0, -1)
                                  if ".".join(parts[:n]) in modules), None)
                    if found is not None and found != module:
                        targets.add(found)
        graph[module] = targets
    return graph


def find_cycle(graph: dict[str, set[str]]) -> list[str] | None:
    """A cycle as [m1, m2, ..., m1], or None."""
    done: set[str] = set()

    def visit(module: str, path: list[str]) -> list[str] | None:
        if module in path:
            return [*path[path.index(module):], module]
        if module in done:
            return None
        for target in sorted(graph.get(module, ())):
            cycle = visit(target, [*path, module])
            if cycle:
                return cycle
        done.add(module)
        return None

    for module in sorted(graph):
        cycle = visit(module, [])
        if cycle:
            return cycle
    return None


def test_robot_setup_has_no_import_cycle():
    graph = import_graph(ROBOT_SETUP)
    # The scan sees the imports that matter: generate -> templates -> plan, a template -> its helpers.
    assert "robot_setup.templates" in graph["robot_setup.generate"]
    assert "robot_setup.plan" in graph["robot_setup.templates.text"]
    assert "robot_setup.templates.text" in graph["robot_setup.templates.sim_yaml"]
    assert find_cycle(graph) is None


def test_a_cycle_through_function_level_imports_is_found(tmp_path):
    """The old shape: generate imported the templates inside `render`, the templates imported generate
    inside theirs (and under TYPE_CHECKING)."""
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
