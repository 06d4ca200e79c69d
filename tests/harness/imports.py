"""Import graphs read from source (ast, nothing imported): every import counts, at module level, inside a
function or under TYPE_CHECKING, since an import moved into a function still ties two modules together."""

from __future__ import annotations

import ast
import pathlib

__all__ = ["find_cycle", "import_graph", "imported_names", "packages"]

SRC = pathlib.Path(__file__).resolve().parents[2] / "src"


def packages(src: pathlib.Path = SRC) -> dict[str, pathlib.Path]:
    """Python package name -> its folder, for every catkin package under `src` with a Python library."""
    return {init.parent.name: init.parent for init in sorted(src.glob("*/src/*/__init__.py"))}


def imported_names(path: pathlib.Path) -> set[str]:
    """Top-level names of everything a module imports (absolute imports; relative ones are its own)."""
    names = set()
    for node in ast.walk(ast.parse(path.read_text(), str(path))):
        if isinstance(node, ast.Import):
            names.update(alias.name.split(".")[0] for alias in node.names)
        elif isinstance(node, ast.ImportFrom) and node.module and not node.level:
            names.add(node.module.split(".")[0])
    return names


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
