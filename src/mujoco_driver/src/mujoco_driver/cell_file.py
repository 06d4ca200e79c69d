"""A cell file: which robot packages share one simulated world, where, under which names (README, Cells).

    arms:
      - {name: left, package: big_arm_custom, position: [0, 0, 0], rpy: [0, 0, 0]}
      - {name: right, package: small_arm_custom, position: [0, 1.6, 0], args: {fixture: hand}}

Each arm's whole stack comes from its package's sim.launch in its namespace (``ns:=<name>``, tf prefix
``<name>``, and its entry's ``args``: that sim.launch's arguments) without a driver of its own; one
``mujoco_cell`` node simulates them all. :func:`launch_xml` writes the roslaunch file that does so.
"""

from __future__ import annotations

import re
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any
from xml.sax.saxutils import quoteattr

import yaml
from compliant_common.errors import StackError

__all__ = ["Cell", "CellArmEntry", "CellFileError", "launch_xml", "load_cell", "parse_cell", "triple"]

_NAME = re.compile(r"^[A-Za-z][A-Za-z0-9_]*$")  # a ROS name segment
_KEYS = ("name", "package", "position", "rpy", "args")


class CellFileError(StackError):
    """A cell file that cannot be read or is not a cell (the file, the key and why)."""


@dataclass(frozen=True)
class CellArmEntry:
    """One arm: its name (namespace and tf prefix), robot package, base pose in the world [m, rad] and its
    sim.launch's own arguments."""

    name: str
    package: str
    position: tuple[float, float, float]
    rpy: tuple[float, float, float]
    args: tuple[tuple[str, str], ...] = ()


@dataclass(frozen=True)
class Cell:
    """The arms of a cell, in the file's order."""

    arms: tuple[CellArmEntry, ...]


def triple(entry: Mapping[str, Any], key: str, where: str,
           error: type[StackError] = CellFileError) -> tuple[float, float, float]:
    """`entry[key]` as three numbers (zeros when absent).

    Raises:
        error: Naming `where` and the key, if it is not three numbers.
    """
    value = entry.get(key, [0.0, 0.0, 0.0])
    try:
        x, y, z = (float(v) for v in value)
    except (TypeError, ValueError):
        raise error(f"{where}.{key}: expected three numbers, got {value!r}") from None
    return x, y, z


def parse_cell(data: Any, source: str = "cell") -> Cell:
    """A cell from its file's content.

    Raises:
        CellFileError: No `arms` list, an entry without a valid name or package, an unknown key, two arms of
            one name, or a bad position or rpy.
    """
    if not isinstance(data, Mapping) or set(data) != {"arms"}:
        got = sorted(data) if isinstance(data, Mapping) else data
        raise CellFileError(f"{source}: expected one key, arms, got {got!r}")
    entries = data["arms"]
    if not isinstance(entries, list) or not entries:
        raise CellFileError(f"{source}: arms: expected a list of {{name, package, position, rpy}}")
    arms = []
    for i, entry in enumerate(entries):
        where = f"{source}: arms[{i}]"
        if not isinstance(entry, Mapping):
            raise CellFileError(f"{where}: expected a mapping, got {entry!r}")
        unknown = sorted(set(entry) - set(_KEYS))
        if unknown:
            raise CellFileError(f"{where}: unknown keys {unknown} (known: {', '.join(_KEYS)})")
        for key in ("name", "package"):
            if not isinstance(entry.get(key), str) or not _NAME.match(entry[key]):
                raise CellFileError(f"{where}.{key}: expected a name of letters, digits and _, got "
                                    f"{entry.get(key)!r}")
        args = entry.get("args", {})
        scalars = isinstance(args, Mapping) and not any(isinstance(v, Mapping | list) for v in args.values())
        if not scalars or not all(isinstance(k, str) and _NAME.match(k) for k in args):
            raise CellFileError(f"{where}.args: expected a mapping of launch arguments to values, got "
                                f"{args!r}")
        reserved = sorted(set(args) & {"ns", "tf_prefix", "with_driver"})
        if reserved:
            raise CellFileError(f"{where}.args: {reserved} are the cell's to set")
        arms.append(CellArmEntry(entry["name"], entry["package"], triple(entry, "position", where),
                                 triple(entry, "rpy", where),
                                 tuple((k, _launch_value(v)) for k, v in args.items())))
    names = [a.name for a in arms]
    twice = sorted({n for n in names if names.count(n) > 1})
    if twice:
        raise CellFileError(f"{source}: arms named {twice} more than once: each arm needs its own namespace")
    return Cell(tuple(arms))


def _launch_value(value: Any) -> str:
    """A YAML scalar as roslaunch reads an argument (true, not True)."""
    return str(value).lower() if isinstance(value, bool) else str(value)


def load_cell(path: str) -> Cell:
    """The cell in the file at `path`.

    Raises:
        CellFileError: An unreadable file or not a cell.
    """
    try:
        with open(path, encoding="utf-8") as handle:
            data = yaml.safe_load(handle)
    except (OSError, yaml.YAMLError) as exc:
        raise CellFileError(f"{path}: cannot read: {exc}") from None
    return parse_cell(data, path)


def launch_xml(cell: Cell, args: Mapping[str, str] | None = None, one_world: bool = True) -> str:
    """The roslaunch file of `cell`: each arm's sim.launch in its namespace without a driver, `args` passed
    to every one of them, and one mujoco_cell node (with `viewer`, if given, on the whole cell). Not
    `one_world`: each arm's own simulation instead, apart (what the cell's world is measured against)."""
    args = dict(args or {})
    viewer = args.pop("viewer", "false")
    if not one_world:
        args["viewer"] = viewer
    lines = ['<?xml version="1.0"?>', "<!-- Generated by mujoco_driver's cell_file from a cell file. -->",
             "<launch>"]
    for arm in cell.arms:
        lines.append(f'  <include file="$(find {arm.package})/launch/sim.launch">')
        fixed = {"ns": arm.name, "tf_prefix": arm.name, "with_driver": str(not one_world).lower()}
        for key, value in {**args, **dict(arm.args), **fixed}.items():
            lines.append(f"    <arg name={quoteattr(key)} value={quoteattr(value)}/>")
        lines.append("  </include>")
    if not one_world:
        return "\n".join([*lines, "</launch>", ""])
    entries = ", ".join(f"{{name: {a.name}, position: {list(a.position)}, rpy: {list(a.rpy)}}}"
                        for a in cell.arms)
    output = quoteattr(args.get("output", "screen"))
    lines += [f'  <node pkg="mujoco_driver" type="mujoco_cell" name="mujoco_cell" required="true" '
              f'output={output}>',
              f'    <rosparam param="arms">[{entries}]</rosparam>',
              f"    <param name=\"viewer\" value={quoteattr(viewer)}/>",
              "  </node>", "</launch>", ""]
    return "\n".join(lines)
