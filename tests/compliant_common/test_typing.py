"""No `Any` in the public signatures of compliant_common, contact_control, jog_arm and control_stack
(with mypy's strict flags for those packages in mypy.ini). Public: a function or method whose
name has no leading underscore (dunders such as __init__ count: they are the class's public face), in a
module and classes whose names have none either. Private helpers may keep Any."""

from __future__ import annotations

import ast
import pathlib

import pytest

SRC = pathlib.Path(__file__).resolve().parents[2] / "src"
PACKAGES = ("compliant_common", "contact_control", "jog_arm", "control_stack")


def _private(name: str) -> bool:
    return name.startswith("_") and not (name.startswith("__") and name.endswith("__"))


def _mentions_any(annotation: ast.expr | None) -> bool:
    if annotation is None:
        return False
    for node in ast.walk(annotation):
        if isinstance(node, ast.Name) and node.id == "Any":
            return True
        if isinstance(node, ast.Attribute) and node.attr == "Any":
            return True
        if isinstance(node, ast.Constant) and isinstance(node.value, str):  # a quoted annotation
            try:
                quoted = ast.parse(node.value, mode="eval").body
            except SyntaxError:
                continue
            if _mentions_any(quoted):
                return True
    return False


def _signature_annotations(fn: ast.FunctionDef | ast.AsyncFunctionDef) -> list[tuple[str, ast.expr | None]]:
    args = fn.args
    named = [*args.posonlyargs, *args.args, *args.kwonlyargs]
    found: list[tuple[str, ast.expr | None]] = [(a.arg, a.annotation) for a in named]
    for star in (args.vararg, args.kwarg):
        if star is not None:
            found.append((star.arg, star.annotation))
    found.append(("return", fn.returns))
    return found


def any_in_public_signatures(source: str, filename: str) -> list[str]:
    """`filename:line: name(param)` for every public signature annotation that mentions Any."""
    offences: list[str] = []

    def visit(body: list[ast.stmt], owner: str) -> None:
        for node in body:
            if isinstance(node, ast.ClassDef) and not _private(node.name):
                visit(node.body, f"{owner}{node.name}.")
            elif isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)) and not _private(node.name):
                for what, annotation in _signature_annotations(node):
                    if _mentions_any(annotation):
                        offences.append(f"{filename}:{node.lineno}: {owner}{node.name}({what})")
            elif isinstance(node, (ast.If, ast.Try)):  # definitions under `if TYPE_CHECKING:` and the like
                visit(node.body, owner)
                visit(node.orelse, owner)

    visit(ast.parse(source, filename).body, "")
    return offences


def _modules() -> list[pathlib.Path]:
    found = []
    for pkg in PACKAGES:
        root = SRC / pkg / "src" / pkg
        found += [p for p in sorted(root.rglob("*.py"))
                  if not any(_private(part) for part in p.relative_to(root).with_suffix("").parts)
                  or p.name == "__init__.py"]
    return found


def test_the_checked_modules_are_found():
    modules = _modules()
    for pkg in PACKAGES:
        assert any(p.parts[-2] == pkg for p in modules), pkg
    assert len(modules) > 40


def test_no_any_in_the_public_signatures_of_the_strict_packages():
    offences = []
    for path in _modules():
        offences += any_in_public_signatures(path.read_text(), str(path.relative_to(SRC)))
    assert offences == [], "Any in public signatures:\n" + "\n".join(offences)


@pytest.mark.parametrize("source, expected", [
    ("from typing import Any\ndef f(x: Any) -> int: ...\n", ["m.py:2: f(x)"]),
    ("import typing\ndef f() -> list[typing.Any]: ...\n", ["m.py:2: f(return)"]),
    ("class C:\n    def m(self, *a: 'dict[str, Any]') -> None: ...\n", ["m.py:2: C.m(a)"]),
    ("class C:\n    def __init__(self, *, k: Any) -> None: ...\n", ["m.py:2: C.__init__(k)"]),
    ("if True:\n    def f(**kw: Any) -> None: ...\n", ["m.py:2: f(kw)"]),
])
def test_the_check_catches_any_in_a_public_signature(source, expected):
    assert any_in_public_signatures(source, "m.py") == expected


@pytest.mark.parametrize("source", [
    "from typing import Any\ndef _f(x: Any) -> Any: ...\n",
    "class _C:\n    def m(self, x: 'Any') -> None: ...\n",
    "class C:\n    def _m(self, x: Any) -> None: ...\n",
    "def f(x: int) -> None:\n    y: Any = x\n",
    "def f(x: 'Anything') -> None: ...\n",
])
def test_the_check_spares_private_helpers_and_bodies(source):
    assert any_in_public_signatures(source, "m.py") == []
