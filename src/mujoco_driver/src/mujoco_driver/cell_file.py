"""A cell file: which robot packages share one simulated world, where, under which names (README, Cells).

    arms:
      - {name: left, package: big_arm_custom, position: [0, 0, 0], rpy: [0, 0, 0]}
      - {name: right, package: small_arm_custom, position: [0, 0.8, 0], args: {fixture: hand}}
    bimanual: {holder: left, presser: right, plate: [0.45, 0.3, 0.25], press: [0.47, 0.47], slide: [-0.04, 0]}

Each arm's whole stack comes from its package's sim.launch in its namespace (``ns:=<name>``, tf prefix
``<name>``, and its entry's ``args``: that sim.launch's arguments) without a driver of its own; one
``mujoco_cell`` node simulates them all. :func:`launch_xml` writes the roslaunch file that does so.
``bimanual`` (optional) is where the cell's two arms meet for thesis_demos' bimanual demonstration: the
holder holds a plate's centre at ``plate`` (world, [m]), the presser presses on it from ``press`` (world x,
y) along ``slide`` (world x, y [m]).
"""

from __future__ import annotations

import re
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any
from xml.sax.saxutils import quoteattr

import yaml
from compliant_common.errors import StackError

__all__ = ["Bimanual", "Cell", "CellArmEntry", "CellFileError", "launch_xml", "load_cell", "parse_cell",
           "triple"]

_NAME = re.compile(r"^[A-Za-z][A-Za-z0-9_]*$")  # a ROS name segment
_KEYS = ("name", "package", "position", "rpy", "args")
_BIMANUAL_KEYS = ("holder", "presser", "plate", "press", "slide")
PLATE_WIDTH = 0.5  # [m] the holder's plate (make_description's --tool-plate, sim_stack.launch's tool:=plate)
PLATE_MARGIN = 0.05  # [m] the pressing tool's edge stays this far inside the plate's
PLATE_CLEAR = 0.12  # [m] the press stays this far from the plate's centre (the holder's own tool)


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
class Bimanual:
    """Where two arms of a cell meet: the holder's plate centre (world [m]), where the presser's press starts
    (world x, y [m]) and its slide (world x, y [m])."""

    holder: str
    presser: str
    plate: tuple[float, float, float]
    press: tuple[float, float]
    slide: tuple[float, float]


@dataclass(frozen=True)
class Cell:
    """The arms of a cell, in the file's order, and where two of them meet (if they do)."""

    arms: tuple[CellArmEntry, ...]
    bimanual: Bimanual | None = None


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
    if not isinstance(data, Mapping) or "arms" not in data or not set(data) <= {"arms", "bimanual"}:
        got = sorted(data) if isinstance(data, Mapping) else data
        raise CellFileError(f"{source}: expected the keys arms and (optional) bimanual, got {got!r}")
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
    entry = data.get("bimanual")
    bimanual = None if entry is None else _bimanual(entry, names, f"{source}: bimanual")
    return Cell(tuple(arms), bimanual)


def _pair(entry: Mapping[str, Any], key: str, where: str) -> tuple[float, float]:
    value = entry.get(key)
    try:
        x, y = (float(v) for v in value)  # type: ignore[union-attr]
    except (TypeError, ValueError):
        raise CellFileError(f"{where}.{key}: expected two numbers (world x, y), got {value!r}") from None
    return x, y


def _bimanual(entry: Any, names: list[str], where: str) -> Bimanual:
    if not isinstance(entry, Mapping):
        raise CellFileError(f"{where}: expected a mapping of {', '.join(_BIMANUAL_KEYS)}, got {entry!r}")
    wrong = sorted(set(entry) ^ set(_BIMANUAL_KEYS))
    if wrong:
        raise CellFileError(f"{where}: expected exactly the keys {', '.join(_BIMANUAL_KEYS)}; wrong: {wrong}")
    for key in ("holder", "presser"):
        if entry[key] not in names:
            raise CellFileError(f"{where}.{key}: {entry[key]!r} is not an arm of the cell "
                                f"({', '.join(names)})")
    if entry["holder"] == entry["presser"]:
        raise CellFileError(f"{where}: the holder and the presser must be two arms")
    if "plate" not in entry or len(entry["plate"] or ()) != 3:
        raise CellFileError(f"{where}.plate: expected three numbers (world x, y, z), got "
                            f"{entry.get('plate')!r}")
    plate = triple(entry, "plate", where)
    press, slide = _pair(entry, "press", where), _pair(entry, "slide", where)
    inside = PLATE_WIDTH / 2.0 - PLATE_MARGIN
    for end in (press, (press[0] + slide[0], press[1] + slide[1])):
        dx, dy = end[0] - plate[0], end[1] - plate[1]
        if max(abs(dx), abs(dy)) > inside:
            raise CellFileError(f"{where}: the press at ({end[0]:g}, {end[1]:g}) leaves the "
                                f"{PLATE_WIDTH:g} m plate centred at ({plate[0]:g}, {plate[1]:g}) (at most "
                                f"{inside:g} m off it)")
        if (dx * dx + dy * dy) ** 0.5 < PLATE_CLEAR:
            raise CellFileError(f"{where}: the press at ({end[0]:g}, {end[1]:g}) comes within "
                                f"{PLATE_CLEAR:g} m of the plate's centre, where the holder's tool is")
    return Bimanual(entry["holder"], entry["presser"], plate, press, slide)


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
    to every one of them (``<arm>.<name>``: to that arm's only), and one mujoco_cell node (with `viewer`, if
    given, on the whole cell). Not `one_world`: each arm's own simulation instead, apart (what the cell's
    world is measured against).

    Raises:
        CellFileError: An ``<arm>.<name>`` argument of no arm of the cell.
    """
    args = dict(args or {})
    names = {arm.name for arm in cell.arms}
    own: dict[str, dict[str, str]] = {name: {} for name in names}
    for key in [k for k in args if "." in k]:
        arm_name, name = key.split(".", 1)
        if arm_name not in names:
            raise CellFileError(f"argument {key}: no arm {arm_name!r} in the cell "
                                f"({', '.join(sorted(names))})")
        own[arm_name][name] = args.pop(key)
    viewer = args.pop("viewer", "false")
    if not one_world:
        args["viewer"] = viewer
    lines = ['<?xml version="1.0"?>', "<!-- Generated by mujoco_driver's cell_file from a cell file. -->",
             "<launch>"]
    for arm in cell.arms:
        lines.append(f'  <include file="$(find {arm.package})/launch/sim.launch">')
        fixed = {"ns": arm.name, "tf_prefix": arm.name, "with_driver": str(not one_world).lower()}
        for key, value in {**args, **dict(arm.args), **own[arm.name], **fixed}.items():
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
