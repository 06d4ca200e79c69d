"""Collision geometry MuJoCo can compile, for every link of a URDF, and a report of what was done per link.

MuJoCo reads STL, OBJ and MSH meshes only; many URDFs ship COLLADA (``.dae``) meshes, and some links have
mass but no geometry at all. :func:`prepare_collision` edits the URDF tree (the copy the scene builder
hands to MuJoCo, never ``robot_description``) link by link:

  * a collision mesh MuJoCo reads is kept;
  * any other mesh is converted with trimesh (COLLADA needs pycollada) into a binary STL in the mesh
    cache (:func:`default_cache_dir`; the file name carries a hash of the source, so a cached copy is
    reused until the source changes);
  * when conversion is impossible (trimesh or pycollada missing, unreadable file, no triangles, flat
    mesh) the mesh becomes a primitive: a box fitted to the mesh's bounds when they could be read, else a
    capsule from the link's origin to each child joint's origin;
  * a link without collision geometry takes its visual geometry, or, if it has none either but has mass,
    the child-joint capsule; massless links (frames such as ``tool0``) stay without geometry.

Capsules are not URDF (Pinocchio's parser refuses them) but MuJoCo's URDF reader takes them, and this tree
only goes to MuJoCo. Every decision is returned as a :class:`LinkGeometry` for the caller to log.
"""

from __future__ import annotations

import copy
import hashlib
import math
import os
import re
import sys
import tempfile
import xml.etree.ElementTree as ET
from collections.abc import Sequence
from dataclasses import dataclass
from typing import cast

import numpy as np
from compliant_common.errors import StackError

__all__ = [
    "CACHE_ENV",
    "MUJOCO_MESH_FORMATS",
    "LinkGeometry",
    "MeshError",
    "convert_mesh",
    "default_cache_dir",
    "main",
    "prepare_collision",
]

MUJOCO_MESH_FORMATS = (".stl", ".obj", ".msh")
CACHE_ENV = "MUJOCO_DRIVER_MESH_CACHE"
# Shortest child-joint offset [m] worth a capsule; thinnest side [m] of a box fitted to flat bounds.
MIN_CAPSULE_LENGTH = 0.01
MIN_BOX_SIDE = 0.002
# Capsule radius bounds [m] when fitted from the link's inertia (or 10 % of its length without one).
MIN_RADIUS, MAX_RADIUS = 0.01, 0.1

KEPT, CONVERTED, BOX, CAPSULE, FROM_VISUAL, NONE = (
    "kept", "converted", "box from mesh bounds", "capsule from child joints", "from visual", "none"
)


class MeshError(StackError):
    """A mesh cannot be converted; `bounds` holds its (2, 3) axis-aligned bounds if they could be read."""

    def __init__(self, message: str, bounds: np.ndarray | None = None) -> None:
        super().__init__(message)
        self.bounds = bounds


@dataclass(frozen=True)
class LinkGeometry:
    """What became of one link's collision geometry.

    Attributes:
        link: URDF link name.
        action: ``kept``, ``converted``, ``box from mesh bounds``, ``capsule from child joints``,
            ``from visual`` (then one of the others for the copied geometry) or ``none``.
        detail: Source and result files, or why a fallback was needed.
    """

    link: str
    action: str
    detail: str = ""

    @property
    def changed(self) -> bool:
        """True unless the link's geometry went to MuJoCo as the URDF gave it (or it has none)."""
        return self.action not in (KEPT, NONE)

    def __str__(self) -> str:
        return f"link {self.link}: {self.action}" + (f" ({self.detail})" if self.detail else "")


def default_cache_dir() -> str:
    """Directory of converted meshes: ``$MUJOCO_DRIVER_MESH_CACHE``, else ``$XDG_CACHE_HOME`` (or
    ``~/.cache``) ``/mujoco_driver/meshes``. Outside the work tree: generated files are never committed."""
    if os.environ.get(CACHE_ENV):
        return os.environ[CACHE_ENV]
    base = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    return os.path.join(base, "mujoco_driver", "meshes")


def _collada_unit(data: bytes) -> float:
    """Metres per COLLADA unit (``<unit meter=...>``; trimesh records it but does not scale)."""
    match = re.search(rb"<unit\b[^>]*\bmeter\s*=\s*[\"']([0-9.eE+-]+)[\"']", data[:65536])
    try:
        return float(match.group(1)) if match else 1.0
    except ValueError:
        return 1.0


def convert_mesh(path: str, cache_dir: str) -> str:
    """Convert a mesh file MuJoCo cannot read into a binary STL in `cache_dir` (reused if already there).

    Args:
        path: Absolute path of the source mesh (any format trimesh loads; COLLADA needs pycollada).
        cache_dir: Output directory, created if needed.

    Returns:
        Path of the STL, in metres (a COLLADA ``<unit>`` is applied).

    Raises:
        MeshError: trimesh (or the format's loader) is missing, the file does not load, or the mesh has
            no triangles or no volume (its `bounds` are set when they could be read).
    """
    with open(path, "rb") as handle:
        data = handle.read()
    try:
        import trimesh  # optional: only URDFs with meshes MuJoCo cannot read need it
    except ImportError as exc:
        raise MeshError(f"trimesh is not installed ({exc})") from exc
    key = hashlib.sha256(data + str(trimesh.__version__).encode()).hexdigest()[:16]
    stem = os.path.splitext(os.path.basename(path))[0]
    target = os.path.join(cache_dir, f"{stem}-{key}.stl")
    if os.path.isfile(target):
        return target
    try:
        mesh = trimesh.load(path, force="mesh")
    except ImportError as exc:  # trimesh raises the loader's ImportError only when the format is used
        raise MeshError(f"trimesh cannot load {os.path.basename(path)}: {exc}") from exc
    except Exception as exc:  # loaders raise anything on a broken file
        raise MeshError(f"trimesh cannot load {path}: {type(exc).__name__}: {exc}") from exc
    if not isinstance(mesh, trimesh.Trimesh) or len(mesh.faces) == 0:
        bounds = None if not len(getattr(mesh, "vertices", ())) else np.asarray(mesh.bounds, dtype=float)
        raise MeshError(f"{path} holds no triangles", bounds)
    if path.lower().endswith(".dae"):
        mesh.apply_scale(_collada_unit(data))
    bounds = np.asarray(mesh.bounds, dtype=float)
    if np.min(bounds[1] - bounds[0]) <= 0.0:
        raise MeshError(f"{path} is flat (extents {bounds[1] - bounds[0]}): MuJoCo needs a volume", bounds)
    os.makedirs(cache_dir, exist_ok=True)
    # Write then rename: two processes converting the same mesh never see a half-written file.
    fd, tmp = tempfile.mkstemp(suffix=".stl", dir=cache_dir)
    try:
        with os.fdopen(fd, "wb") as handle:
            handle.write(cast(bytes, mesh.export(file_type="stl")))  # binary STL
        os.replace(tmp, target)
    except BaseException:
        if os.path.exists(tmp):
            os.unlink(tmp)
        raise
    return target


# ----------------------------------------------------------------------------------- URDF helpers

def _floats(text: str | None, default: Sequence[float]) -> np.ndarray:
    return np.array([float(v) for v in text.split()]) if text else np.array(default, dtype=float)


def _rotation(rpy: np.ndarray) -> np.ndarray:
    """URDF roll-pitch-yaw (fixed axes X, then Y, then Z) as a rotation matrix."""
    r, p, y = rpy
    cr, sr, cp, sp, cy, sy = math.cos(r), math.sin(r), math.cos(p), math.sin(p), math.cos(y), math.sin(y)
    return np.array([
        [cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
        [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
        [-sp, cp * sr, cp * cr],
    ])


def _fmt(values: Sequence[float] | np.ndarray) -> str:
    return " ".join(repr(round(float(v), 9)) for v in values)


def _origin(elem: ET.Element) -> tuple[np.ndarray, np.ndarray]:
    origin = elem.find("origin")
    if origin is None:
        return np.zeros(3), np.zeros(3)
    return _floats(origin.get("xyz"), (0, 0, 0)), _floats(origin.get("rpy"), (0, 0, 0))


def _collision(
    xyz: Sequence[float] | np.ndarray, rpy: Sequence[float] | np.ndarray, tag: str, **attrs: str
) -> ET.Element:
    collision = ET.Element("collision")
    ET.SubElement(collision, "origin", xyz=_fmt(xyz), rpy=_fmt(rpy))
    ET.SubElement(ET.SubElement(collision, "geometry"), tag, attrs)
    return collision


def _mass(link: ET.Element) -> float:
    mass = link.find("inertial/mass")
    try:
        return float(mass.get("value", "0")) if mass is not None else 0.0
    except ValueError:
        return 0.0


def _capsule_radius(link: ET.Element, length: float) -> float:
    """Radius of a rod with the link's smallest principal moment, I = m r^2 / 2 (clamped)."""
    mass, inertia = _mass(link), link.find("inertial/inertia")
    radius = 0.1 * length
    if mass > 0.0 and inertia is not None:
        moments = [float(inertia.get(k, "0")) for k in ("ixx", "iyy", "izz")]
        positive = [m for m in moments if m > 0.0]
        if positive:
            radius = math.sqrt(2.0 * min(positive) / mass)
    return min(max(radius, MIN_RADIUS), MAX_RADIUS)


def _child_capsules(link: ET.Element, child_offsets: list[np.ndarray]) -> list[ET.Element]:
    """One capsule from the link's origin to each child joint's origin at least MIN_CAPSULE_LENGTH away."""
    capsules = []
    for offset in child_offsets:
        length = float(np.linalg.norm(offset))
        if length < MIN_CAPSULE_LENGTH:
            continue
        direction = offset / length
        # Capsules lie along their origin's z: pitch then yaw turn z onto the offset.
        rpy = (0.0, math.acos(max(-1.0, min(1.0, direction[2]))), math.atan2(direction[1], direction[0]))
        radius = _capsule_radius(link, length)
        capsules.append(_collision(offset / 2.0, rpy, "capsule", radius=repr(radius), length=repr(length)))
    return capsules


def _bounds_box(collision: ET.Element, mesh: ET.Element, bounds: np.ndarray) -> ET.Element:
    """A box collision replacing `mesh`: the mesh's bounds, scaled, in the collision's origin frame."""
    xyz, rpy = _origin(collision)
    scale = _floats(mesh.get("scale"), (1, 1, 1))
    low, high = bounds[0] * scale, bounds[1] * scale
    centre = xyz + _rotation(rpy) @ ((low + high) / 2.0)
    size = np.maximum(np.abs(high - low), MIN_BOX_SIDE)
    return _collision(centre, rpy, "box", size=_fmt(size))


def _mesh_path(mesh: ET.Element) -> str:
    uri = mesh.get("filename", "")
    return uri[len("file://"):] if uri.startswith("file://") else uri


def _fix_mesh(
    link: ET.Element, collision: ET.Element, mesh: ET.Element, child_offsets: list[np.ndarray], cache_dir: str
) -> tuple[list[ET.Element], str, str]:
    """(replacement collisions, action, detail) for a collision whose mesh MuJoCo cannot read."""
    path = _mesh_path(mesh)
    try:
        target = convert_mesh(path, cache_dir)
    except (MeshError, OSError) as exc:
        if isinstance(exc, MeshError) and exc.bounds is not None:
            return [_bounds_box(collision, mesh, exc.bounds)], BOX, f"{os.path.basename(path)}: {exc}"
        capsules = _child_capsules(link, child_offsets)
        if capsules:
            return capsules, CAPSULE, f"{os.path.basename(path)}: {exc}"
        return [], NONE, f"{os.path.basename(path)} dropped, no child joint to fit a capsule to: {exc}"
    mesh.set("filename", target)
    return [collision], CONVERTED, f"{os.path.basename(path)} -> {target}"


def prepare_collision(robot: ET.Element, cache_dir: str | None = None) -> list[LinkGeometry]:
    """Make every link's collision geometry readable by MuJoCo, in place (see the module docstring).

    Args:
        robot: The parsed URDF (``<robot>``) with absolute mesh paths; modified in place.
        cache_dir: Where converted meshes go; None = :func:`default_cache_dir`.

    Returns:
        One entry per link, in URDF order.
    """
    cache = cache_dir or default_cache_dir()
    offsets: dict[str, list[np.ndarray]] = {}
    for joint in robot.findall("joint"):
        parent = joint.find("parent")
        if parent is not None:
            offsets.setdefault(parent.get("link", ""), []).append(_origin(joint)[0])
    report = []
    for link in robot.findall("link"):
        name = link.get("name", "")
        children = offsets.get(name, [])
        prefix = ""
        if link.find("collision") is None:
            visuals = [v for v in link.findall("visual") if v.find("geometry") is not None]
            if visuals:
                prefix = FROM_VISUAL + ", "
                for visual in visuals:
                    collision = ET.SubElement(link, "collision")
                    for part in ("origin", "geometry"):
                        elem = visual.find(part)
                        if elem is not None:
                            collision.append(copy.deepcopy(elem))
            elif _mass(link) > 0.0:
                capsules = _child_capsules(link, children)
                link.extend(capsules)
                action = CAPSULE if capsules else NONE
                why = "no geometry in the URDF" + ("" if capsules else ", no child joint to fit a capsule to")
                report.append(LinkGeometry(name, action, why))
                continue
            else:
                report.append(LinkGeometry(name, NONE, "massless frame"))
                continue
        actions, details = [], []
        for collision in list(link.findall("collision")):
            mesh = collision.find("geometry/mesh")
            if mesh is None or os.path.splitext(_mesh_path(mesh))[1].lower() in MUJOCO_MESH_FORMATS:
                actions.append(KEPT)
                continue
            replacement, action, detail = _fix_mesh(link, collision, mesh, children, cache)
            if action == CAPSULE and CAPSULE in actions:
                replacement = []  # the link's capsules are there already (several unreadable meshes)
            if replacement != [collision]:
                link.remove(collision)
                link.extend(replacement)
            actions.append(action)
            details.append(detail)
        worst = max(actions, key=[KEPT, CONVERTED, BOX, CAPSULE, NONE].index)
        report.append(LinkGeometry(name, prefix + worst, "; ".join(details)))
    return report


def main(argv: Sequence[str] | None = None) -> int:
    """``python -m mujoco_driver.meshes URDF [CACHE_DIR]``: convert (fill the cache) and print the report."""
    args = list(sys.argv[1:] if argv is None else argv)
    if not 1 <= len(args) <= 2:
        sys.stderr.write("usage: python -m mujoco_driver.meshes URDF [CACHE_DIR]\n")
        return 2
    with open(args[0], encoding="utf-8") as handle:
        robot = ET.fromstring(handle.read())
    for entry in prepare_collision(robot, args[1] if len(args) > 1 else None):
        print(entry)
    return 0


if __name__ == "__main__":
    sys.exit(main())
