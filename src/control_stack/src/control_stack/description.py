"""Build the robot description (URDF) the whole stack shares, from a stock URDF plus a wrist tool.

This module only needs the Python standard library: the `make_description` executable runs it with
whatever `python3` roslaunch finds first on PATH, which may not see the workspace's virtualenv.

What it does to the stock URDF:
  * resolves ``package://<pkg>/...`` mesh URIs to absolute ``file://`` URIs (example-robot-data is
    found from the running Python, a virtualenv next to the workspace, or ``EXAMPLE_ROBOT_DATA_DIR``;
    other packages through ``ROS_PACKAGE_PATH``), so no consumer needs a ROS package to exist;
  * optionally removes link subtrees (e.g. a gripper the sim does not actuate);
  * appends a force/torque sensor frame link, fixed to a flange link, and a tool link fixed to the sensor,
    with real mass, centre of mass, inertia and a simple collision shape, plus a massless tip frame at the
    tool's end. The tool hangs *below* the sensor in the tree, so any wrench on it passes through the sensor.

Frames: the sensor link's axes are the flange's (optionally offset by ``ft_xyz``/``ft_rpy``); the tool link
coincides with the sensor frame; the tool's shape extends along the sensor's +Z; the tip sits at its end.
"""

from __future__ import annotations

import argparse
import dataclasses
import glob
import os
import shlex
import sys
import sysconfig
import xml.etree.ElementTree as ET
from collections.abc import Sequence
from dataclasses import dataclass, field

from compliant_common.errors import StackError

__all__ = [
    "DescriptionError",
    "ToolSpec",
    "build_description",
    "find_example_robot_data",
    "main",
    "parse_robot",
    "resolve_package_uri",
]

ERD_PACKAGE = "example-robot-data"
ERD_ENV = "EXAMPLE_ROBOT_DATA_DIR"
_ERD_SUFFIX = os.path.join("cmeel.prefix", "share", ERD_PACKAGE)
SHAPES = {"cylinder": 2, "box": 3, "sphere": 1}  # shape -> number of size values
PLATE_THICKNESS = 0.01  # [m] ToolSpec.plate's


class DescriptionError(StackError):
    """Raised for a bad source, an unknown link or an invalid tool specification."""


@dataclass
class ToolSpec:
    """The F/T sensor frame and the tool mounted on it.

    Attributes:
        parent: Flange link the sensor is fixed to (must exist in the URDF).
        ft_name: Name of the sensor frame link.
        ft_xyz: Sensor frame position in the parent link [m].
        ft_rpy: Sensor frame orientation in the parent link (roll, pitch, yaw) [rad].
        name: Tool link name (its frame coincides with the sensor frame).
        mass: Tool mass [kg], > 0.
        com: Tool centre of mass in the tool frame [m]; None puts it at the shape's centre.
        inertia: Principal moments (ixx, iyy, izz) about the centre of mass [kg m^2]; None computes
            them from the shape as a solid body of the tool's mass.
        shape: "cylinder" (size: radius, length), "box" (size: x, y, z) or "sphere" (size: radius).
        size: Shape dimensions [m]; the shape starts at the sensor face and extends along +Z.
        tip_name: Name of the massless frame link at the end of the shape (the tool centre point).
        rounded: A cylinder's end is a hemisphere of its radius (a ball-end polishing tool), same length.
        plate: > 0: a square plate this wide [m], PLATE_THICKNESS thick, hangs centred below the shape's end,
            its top face at the tip (a paddle held by its handle: mujoco_driver README, Cells). The mass,
            centre of mass and inertia stay the shape's: the payload the stack knows does not change.
    """

    parent: str
    ft_name: str = "ft_sensor"
    ft_xyz: tuple[float, float, float] = (0.0, 0.0, 0.0)
    ft_rpy: tuple[float, float, float] = (0.0, 0.0, 0.0)
    name: str = "tool"
    mass: float = 1.0
    com: tuple[float, float, float] | None = None
    inertia: tuple[float, float, float] | None = None
    shape: str = "cylinder"
    size: tuple[float, ...] = field(default=(0.03, 0.1))
    tip_name: str = "tool_tip"
    rounded: bool = False
    plate: float = 0.0

    def validate(self) -> None:
        """Check the numbers.

        Raises:
            DescriptionError: On a non-positive mass or size, an unknown shape or a wrong size count.
        """
        if self.shape not in SHAPES:
            raise DescriptionError(f"tool shape {self.shape!r} unknown; use one of {sorted(SHAPES)}")
        if len(self.size) != SHAPES[self.shape]:
            raise DescriptionError(
                f"tool shape {self.shape} needs {SHAPES[self.shape]} size values, got {len(self.size)}"
            )
        if not all(s > 0 for s in self.size):
            raise DescriptionError(f"tool size must be positive, got {self.size}")
        if not self.mass > 0:
            raise DescriptionError(f"tool mass must be positive, got {self.mass}")
        if self.inertia is not None and not all(i > 0 for i in self.inertia):
            raise DescriptionError(f"tool inertia must be positive, got {self.inertia}")
        if self.rounded and (self.shape != "cylinder" or self.size[1] < self.size[0]):
            raise DescriptionError("a rounded end needs a cylinder at least as long as its radius")
        if not 0.0 <= self.plate <= 1.0:
            raise DescriptionError(f"tool plate width must be in [0, 1] m, got {self.plate}")
        names = {self.ft_name, self.name, self.tip_name}
        if len(names) != 3 or "" in names:
            raise DescriptionError("sensor, tool and tip link names must be distinct and non-empty")

    def length(self) -> float:
        """Extent of the shape along the tool's Z axis [m]."""
        if self.shape == "cylinder":
            return self.size[1]
        if self.shape == "box":
            return self.size[2]
        return 2.0 * self.size[0]

    def centre(self) -> tuple[float, float, float]:
        """Centre of the shape in the tool frame [m]."""
        return (0.0, 0.0, self.length() / 2.0)

    def principal_inertia(self) -> tuple[float, float, float]:
        """Principal moments about the centre of mass [kg m^2] (given, or the solid shape's)."""
        if self.inertia is not None:
            return self.inertia
        m = self.mass
        if self.shape == "cylinder":
            r, h = self.size
            side = m * (3.0 * r * r + h * h) / 12.0
            return (side, side, m * r * r / 2.0)
        if self.shape == "box":
            x, y, z = self.size
            return (m * (y * y + z * z) / 12.0, m * (x * x + z * z) / 12.0, m * (x * x + y * y) / 12.0)
        r = self.size[0]
        return (0.4 * m * r * r,) * 3


def _site_package_dirs() -> list[str]:
    """site-packages directories of the running interpreter."""
    dirs = [sysconfig.get_paths().get("purelib", ""), sysconfig.get_paths().get("platlib", "")]
    dirs += [p for p in sys.path if p.endswith("site-packages") or p.endswith("dist-packages")]
    return [d for d in dict.fromkeys(dirs) if d]


def find_example_robot_data(start: str | None = None) -> str:
    """Locate example-robot-data's share directory (the one holding ``robots/``).

    Candidates, first match wins: ``$EXAMPLE_ROBOT_DATA_DIR``; a ``.venv`` in ``start`` or any parent
    (``.venv/lib/python3*/site-packages/cmeel.prefix/share/example-robot-data``); the running
    interpreter's site-packages.

    Args:
        start: Directory to walk up from; defaults to this file's real location.

    Returns:
        Absolute path of the share directory.

    Raises:
        DescriptionError: When no candidate holds a ``robots`` directory.
    """
    candidates: list[str] = []
    if os.environ.get(ERD_ENV):
        candidates.append(os.environ[ERD_ENV])
    here = os.path.realpath(start or os.path.dirname(__file__))
    while True:
        pattern = os.path.join(here, ".venv", "lib", "python3*", "site-packages", _ERD_SUFFIX)
        candidates += sorted(glob.glob(pattern))
        parent = os.path.dirname(here)
        if parent == here:
            break
        here = parent
    candidates += [os.path.join(d, _ERD_SUFFIX) for d in _site_package_dirs()]
    for cand in candidates:
        if os.path.isdir(os.path.join(cand, "robots")):
            return os.path.abspath(cand)
    raise DescriptionError(
        f"example-robot-data not found; set {ERD_ENV} to its share directory. Tried: {candidates}"
    )


def _ros_package_dir(name: str) -> str | None:
    """Directory of ROS package ``name`` found on ROS_PACKAGE_PATH (a dir named so with package.xml)."""
    for root in os.environ.get("ROS_PACKAGE_PATH", "").split(os.pathsep):
        if not root or not os.path.isdir(root):
            continue
        for dirpath, dirnames, filenames in os.walk(root):
            if os.path.basename(dirpath) == name and "package.xml" in filenames:
                return dirpath
            dirnames[:] = [d for d in dirnames if not d.startswith(".")]
    return None


def resolve_package_uri(uri: str, erd_dir: str | None) -> str:
    """Turn ``package://pkg/rel`` into ``file:///abs/rel``; other URIs come back unchanged.

    Args:
        uri: A mesh filename from the URDF.
        erd_dir: example-robot-data share directory, or None if unknown.

    Returns:
        The resolved URI.

    Raises:
        DescriptionError: For a ``package://`` URI whose package cannot be found.
    """
    if not uri.startswith("package://"):
        return uri
    pkg, _, rel = uri[len("package://"):].partition("/")
    base = erd_dir if pkg == ERD_PACKAGE else _ros_package_dir(pkg)
    if base is None:
        raise DescriptionError(f"cannot resolve {uri}: package {pkg!r} not found")
    return "file://" + os.path.join(os.path.abspath(base), rel)


def _fmt(values: Sequence[float]) -> str:
    return " ".join(repr(float(v)) for v in values)


def _remove_subtrees(robot: ET.Element, roots: Sequence[str]) -> None:
    """Remove links ``roots`` and everything below them, with their joints."""
    links = {link.get("name") for link in robot.findall("link")}
    for name in roots:
        if name not in links:
            raise DescriptionError(f"cannot remove link {name!r}: not in the URDF")
    children: dict[str, list[tuple[ET.Element, str]]] = {}
    for joint in robot.findall("joint"):
        parent, child = joint.find("parent"), joint.find("child")
        if parent is not None and child is not None:
            children.setdefault(parent.get("link", ""), []).append((joint, child.get("link", "")))
    doomed_links: set[str] = set()
    doomed_joints: set[str] = set()
    stack = list(roots)
    while stack:
        name = stack.pop()
        doomed_links.add(name)
        for joint, child_link in children.get(name, []):
            doomed_joints.add(joint.get("name", ""))
            stack.append(child_link)
    for joint in robot.findall("joint"):
        child = joint.find("child")
        if child is not None and child.get("link") in doomed_links:
            doomed_joints.add(joint.get("name", ""))
    for elem in list(robot):
        elem_name = elem.get("name")
        if (elem.tag == "link" and elem_name in doomed_links) or (
            elem.tag == "joint" and elem_name in doomed_joints
        ):
            robot.remove(elem)
        elif elem.tag == "gazebo" and elem.get("reference") in doomed_links:
            robot.remove(elem)
        elif elem.tag == "transmission":
            refs = {j.get("name") for j in elem.findall("joint")}
            if refs & doomed_joints:
                robot.remove(elem)


def _fixed_joint(
    name: str, parent: str, child: str, xyz: Sequence[float], rpy: Sequence[float]
) -> ET.Element:
    joint = ET.Element("joint", name=name, type="fixed")
    ET.SubElement(joint, "parent", link=parent)
    ET.SubElement(joint, "child", link=child)
    ET.SubElement(joint, "origin", xyz=_fmt(xyz), rpy=_fmt(rpy))
    return joint


def _shape_geometry(tool: ToolSpec) -> ET.Element:
    geometry = ET.Element("geometry")
    if tool.shape == "cylinder":
        ET.SubElement(geometry, "cylinder", radius=repr(tool.size[0]), length=repr(tool.size[1]))
    elif tool.shape == "box":
        ET.SubElement(geometry, "box", size=_fmt(tool.size))
    else:
        ET.SubElement(geometry, "sphere", radius=repr(tool.size[0]))
    return geometry


def _tool_links(tool: ToolSpec) -> list[ET.Element]:
    """Sensor link, tool link, tip link and the fixed joints between them."""
    sensor = ET.Element("link", name=tool.ft_name)
    body = ET.Element("link", name=tool.name)
    inertial = ET.SubElement(body, "inertial")
    ET.SubElement(inertial, "origin", xyz=_fmt(tool.com or tool.centre()), rpy="0 0 0")
    ET.SubElement(inertial, "mass", value=repr(float(tool.mass)))
    ixx, iyy, izz = tool.principal_inertia()
    ET.SubElement(inertial, "inertia", ixx=repr(ixx), iyy=repr(iyy), izz=repr(izz), ixy="0", ixz="0", iyz="0")
    for tag in ("visual", "collision"):
        if tool.rounded:  # the shaft, and the hemisphere's ball centred one radius above the tip
            r, length = tool.size
            shaft = ET.SubElement(body, tag)
            ET.SubElement(shaft, "origin", xyz=_fmt((0.0, 0.0, (length - r) / 2.0)), rpy="0 0 0")
            shape = ET.SubElement(shaft, "geometry")
            ET.SubElement(shape, "cylinder", radius=repr(r), length=repr(length - r))
            ball = ET.SubElement(body, tag)
            ET.SubElement(ball, "origin", xyz=_fmt((0.0, 0.0, length - r)), rpy="0 0 0")
            ET.SubElement(ET.SubElement(ball, "geometry"), "sphere", radius=repr(r))
            continue
        elem = ET.SubElement(body, tag)
        ET.SubElement(elem, "origin", xyz=_fmt(tool.centre()), rpy="0 0 0")
        elem.append(_shape_geometry(tool))
        if tool.plate > 0.0:
            plate = ET.SubElement(body, tag)
            ET.SubElement(plate, "origin", xyz=_fmt((0.0, 0.0, tool.length() + PLATE_THICKNESS / 2.0)),
                          rpy="0 0 0")
            ET.SubElement(ET.SubElement(plate, "geometry"), "box",
                          size=_fmt((tool.plate, tool.plate, PLATE_THICKNESS)))
    tip = ET.Element("link", name=tool.tip_name)
    zero = (0.0, 0.0, 0.0)
    parent, sensor_name, tool_name, tip_name = tool.parent, tool.ft_name, tool.name, tool.tip_name
    return [
        sensor,
        _fixed_joint(f"{parent}-{sensor_name}_joint", parent, sensor_name, tool.ft_xyz, tool.ft_rpy),
        body,
        _fixed_joint(f"{sensor_name}-{tool_name}_joint", sensor_name, tool_name, zero, zero),
        tip,
        _fixed_joint(f"{tool_name}-{tip_name}_joint", tool_name, tip_name, (0.0, 0.0, tool.length()), zero),
    ]


def read_source(source: str, erd_dir: str | None = None) -> str:
    """Read a URDF given as ``example-robot-data:<relative path>`` or a file path.

    Raises:
        DescriptionError: If the file does not exist.
    """
    if source.startswith(ERD_PACKAGE + ":"):
        path = os.path.join(erd_dir or find_example_robot_data(), source[len(ERD_PACKAGE) + 1:])
    else:
        path = os.path.expanduser(source)
    if not os.path.isfile(path):
        raise DescriptionError(f"URDF source {source!r} not found (looked at {path})")
    with open(path, encoding="utf-8") as handle:
        return handle.read()


def parse_robot(urdf_xml: str) -> ET.Element:
    """The <robot> element of a URDF text.

    Raises:
        DescriptionError: Not XML, or another root element.
    """
    try:
        robot = ET.fromstring(urdf_xml)
    except ET.ParseError as exc:
        raise DescriptionError(f"URDF is not valid XML: {exc}") from exc
    if robot.tag != "robot":
        raise DescriptionError(f"root element is <{robot.tag}>, expected <robot>")
    return robot


def build_description(
    urdf_xml: str,
    tool: ToolSpec | None = None,
    remove_links: Sequence[str] = (),
    erd_dir: str | None = None,
    robot_name: str | None = None,
) -> str:
    """Return the URDF with resolved mesh URIs, removed subtrees and the sensor+tool appended.

    Args:
        urdf_xml: The stock URDF text.
        tool: Sensor and tool to append; None appends nothing.
        remove_links: Links whose subtrees are removed first.
        erd_dir: example-robot-data share directory; found automatically when None and needed.
        robot_name: New ``<robot name>``, or None to keep it.

    Returns:
        The URDF text.

    Raises:
        DescriptionError: On malformed XML, unknown links, clashing names or a bad tool.
    """
    robot = parse_robot(urdf_xml)
    _remove_subtrees(robot, remove_links)
    meshes = robot.iter("mesh")
    for mesh in meshes:
        uri = mesh.get("filename", "")
        if uri.startswith("package://" + ERD_PACKAGE + "/") and erd_dir is None:
            erd_dir = find_example_robot_data()
        mesh.set("filename", resolve_package_uri(uri, erd_dir))
    if tool is not None:
        tool.validate()
        links = {n for link in robot.findall("link") if (n := link.get("name")) is not None}
        if tool.parent not in links:
            raise DescriptionError(f"tool parent link {tool.parent!r} not in the URDF")
        clash = links & {tool.ft_name, tool.name, tool.tip_name}
        if clash:
            raise DescriptionError(f"links {sorted(clash)} already exist in the URDF")
        robot.extend(_tool_links(tool))
    if robot_name:
        robot.set("name", robot_name)
    ET.indent(robot, space="  ")
    return '<?xml version="1.0" encoding="utf-8"?>\n' + ET.tostring(robot, encoding="unicode") + "\n"


class _ArgParser(argparse.ArgumentParser):
    """Reads ``@file`` arguments with shell-like splitting and ``#`` comments."""

    def convert_arg_line_to_args(self, arg_line: str) -> list[str]:
        return shlex.split(arg_line, comments=True)


def _parser() -> argparse.ArgumentParser:
    parser = _ArgParser(
        prog="make_description",
        description="Print a URDF (stock robot + F/T sensor frame + tool) for robot_description.",
        fromfile_prefix_chars="@",
        epilog="Arguments may come from a file: make_description @robot.args (per line, # comments).",
    )
    parser.add_argument("--source", required=True,
                        help="example-robot-data:<path under its share dir> or a URDF file path")
    parser.add_argument("--remove-link", action="append", default=[], metavar="LINK",
                        help="remove this link and its subtree (repeatable), e.g. an unused gripper")
    parser.add_argument("--robot-name", default=None, help="rename the <robot>")
    parser.add_argument("--tool-parent", default=None,
                        help="flange link the F/T sensor is fixed to; without it no sensor/tool is added")
    parser.add_argument("--ft-name", default="ft_sensor", help="F/T sensor frame link name")
    parser.add_argument("--ft-xyz", type=float, nargs=3, default=(0.0, 0.0, 0.0), help="sensor offset [m]")
    parser.add_argument("--ft-rpy", type=float, nargs=3, default=(0.0, 0.0, 0.0), help="sensor rpy [rad]")
    parser.add_argument("--tool-name", default="tool", help="tool link name")
    parser.add_argument("--tool-mass", type=float, default=1.0, help="tool mass [kg]")
    parser.add_argument("--tool-com", type=float, nargs=3, default=None,
                        help="tool centre of mass in the sensor frame [m] (default: shape centre)")
    parser.add_argument("--tool-inertia", type=float, nargs=3, default=None,
                        help="principal inertia ixx iyy izz about the COM [kg m^2] (default: solid shape)")
    parser.add_argument("--tool-shape", choices=sorted(SHAPES), default="cylinder", help="collision shape")
    parser.add_argument("--tool-size", type=float, nargs="+", default=[0.03, 0.1],
                        help="cylinder: radius length; box: x y z; sphere: radius [m]")
    parser.add_argument("--tip-name", default="tool_tip", help="frame link at the tool's end")
    parser.add_argument("--tool-peg", type=float, default=0.0, metavar="WIDTH",
                        help="make the tool a square peg this wide [m], same length, mass and centre of mass "
                        "(contact_tasks' peg_in_hole; 0: the shape given)")
    parser.add_argument("--tool-plate", type=float, default=0.0, metavar="WIDTH",
                        help="a square plate this wide [m] hangs below the tool's end, its top face at the "
                        "tip, same mass (a bimanual cell's holder; 0: none)")
    parser.add_argument("--tool-rounded", action="store_true",
                        help="end the cylinder tool in a hemisphere of its radius, same length, mass and "
                        "centre of mass (a ball-end polishing tool: curved parts)")
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Command-line entry point: print the URDF to stdout; errors go to stderr with exit status 2."""
    args = _parser().parse_args(argv)
    try:
        erd_dir = find_example_robot_data() if args.source.startswith(ERD_PACKAGE + ":") else None
        text = read_source(args.source, erd_dir)
        tool = None
        if args.tool_parent:
            tool = ToolSpec(
                parent=args.tool_parent, ft_name=args.ft_name, ft_xyz=tuple(args.ft_xyz),
                ft_rpy=tuple(args.ft_rpy), name=args.tool_name, mass=args.tool_mass,
                com=tuple(args.tool_com) if args.tool_com else None,
                inertia=tuple(args.tool_inertia) if args.tool_inertia else None,
                shape=args.tool_shape, size=tuple(args.tool_size), tip_name=args.tip_name,
                rounded=args.tool_rounded, plate=args.tool_plate,
            )
            if args.tool_peg > 0.0:
                width, length = args.tool_peg, tool.length()
                tool = dataclasses.replace(tool, shape="box", size=(width, width, length),
                                           com=tool.com or tool.centre(), rounded=False)
        sys.stdout.write(build_description(text, tool, args.remove_link, erd_dir, args.robot_name))
    except DescriptionError as exc:
        sys.stderr.write(f"make_description: error: {exc}\n")
        return 2
    return 0
