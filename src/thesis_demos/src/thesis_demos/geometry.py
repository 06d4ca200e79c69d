"""Where and how far each demonstration moves on a given arm: the robot package's `config/demos.yaml`.

Pure: PyYAML and numpy only. The thesis gives the laws; the distances and directions depend on the arm
(a small arm reaches half as far as a large one), so they live in the robot package, with the obstacle of the
compliant move in its `config/sim.yaml`. :func:`preflight` tells, before anything moves, which
demonstration the arm's start pose and scene cannot do, in plain words.

Directions are signs along the axes of contact_control's control frame (the base frame in every robot
package): the compliant move goes along Z, the spring is pushed and the hybrid move travels along X.
"""

from __future__ import annotations

import math
import os
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, fields, replace
from typing import Any

import yaml
from compliant_common.errors import StackError

__all__ = [
    "DEMOS_FILE",
    "DemoConfigError",
    "DemoGeometry",
    "Obstacle",
    "RobotSetup",
    "demo_motions",
    "find_robot_package",
    "fit_l",
    "load_geometry",
    "load_obstacle",
    "preflight",
    "robot_setup",
    "tool_radius",
]

DEMOS_FILE = os.path.join("config", "demos.yaml")
SCENE_FILE = os.path.join("config", "sim.yaml")
# The compliant move must travel this far before it touches (its verdict asks for > 2 cm) [m].
MIN_APPROACH = 0.025
# Room kept between the obstacle and the end of the compliant move's max path deviation [m].
APPROACH_MARGIN = 0.02
# Surface following (the fifth demonstration) slides the tool this far along X on the obstacle's top.
SURFACE_TRAVEL = 0.04  # [m]
SURFACE_DIRECTION = -1  # along X: toward the base
# The hybrid move's tool tip passes at least this high over the obstacle's top [m].
PASSING_CLEARANCE = 0.02
# Teach and replay: the L (10 x 5 cm, along X then Y) is scaled down to fit on the obstacle's top with the
# whole tool face this far inside its edges (the hand's push stops a few mm past the planned leg) [m] ...
TEACH_MARGIN = 0.005
TEACH_MIN_LEG = 0.03  # [m] ... and a shorter X leg than this is not worth the name: [CANNOT]


class DemoConfigError(StackError):
    """A demos.yaml (or the scene's obstacle) that cannot be used; the message names the key."""


def _positive(value: Any, name: str) -> float:
    number = isinstance(value, (int, float)) and not isinstance(value, bool)
    if not number or not math.isfinite(value) or value <= 0:
        raise DemoConfigError(f"{name}: expected a positive number, got {value!r}")
    return float(value)


def _contact_force(section: Any) -> dict[str, Any]:
    """demos.yaml's contact_force section: {limit: N, drivers: {profile: N}}."""
    if section is None:
        return {}
    if not isinstance(section, Mapping) or set(section) - {"limit", "drivers"}:
        raise DemoConfigError(f"contact_force: expected a mapping with limit and drivers, got {section!r}")
    values: dict[str, Any] = {}
    if "limit" in section:
        values["contact_force_limit"] = _positive(section["limit"], "contact_force.limit")
    drivers = section.get("drivers") or {}
    if not isinstance(drivers, Mapping):
        raise DemoConfigError(f"contact_force.drivers: expected {{profile: limit}}, got {drivers!r}")
    values["driver_force_limits"] = tuple(
        (str(name), _positive(limit, f"contact_force.drivers.{name}")) for name, limit in drivers.items())
    return values


@dataclass(frozen=True)
class DemoGeometry:
    """The arm-dependent numbers of the four demonstrations (defaults: the thesis-sized ones).

    Attributes:
        follower_push_force: Push up along +Z in the follower demo [N] (above the 2.5 N follower deadband).
        follower_push_duration: How long it pushes [s]; the tool rises about F/b times this.
        compliant_direction: Sign along Z of the compliant move (-1: down onto the obstacle).
        compliant_speed: Its V_desired magnitude [m/s].
        compliant_max_travel: Its max path deviation [m]: reaching it without contact fails the demo.
        spring_direction: Sign along X of the spring demo's push.
        spring_push_force: Magnitude of that push [N].
        hybrid_direction: Sign along X of the hybrid compliant move.
        hybrid_speed: Its V_desired magnitude [m/s].
        hybrid_travel: Its max path deviation [m], where it must end.
        contact_force_limit: The compliant move's and the hybrid's force limit [N], the stop on contact (the
            thesis's 0.5 N).
        driver_force_limits: (driver profile, limit [N]) pairs: the limit with that driver's sensor
            (`make demo DRIVER=...`), which resolves less than the simulation's wrist sensor.
        curved_middle: The curved demonstration's path middle, from the cylinder's top toward +X [rad]
            (signed: an arm that nears a singularity on one side runs the path more on the other).
        curved_length: Its length [m] (the tool turns length / 0.25 rad along it).
    """

    follower_push_force: float = 5.0
    follower_push_duration: float = 0.8
    compliant_direction: int = -1
    compliant_speed: float = 0.01
    compliant_max_travel: float = 0.15
    spring_direction: int = 1
    spring_push_force: float = 15.0
    hybrid_direction: int = -1
    hybrid_speed: float = 0.05
    hybrid_travel: float = 0.30
    contact_force_limit: float = 0.5
    driver_force_limits: tuple[tuple[str, float], ...] = ()
    curved_middle: float = 0.0
    curved_length: float = 0.3

    def for_driver(self, driver: str) -> DemoGeometry:
        """These numbers with the force limit for `driver`'s sensor ("" or not listed: unchanged)."""
        limits = dict(self.driver_force_limits)
        return replace(self, contact_force_limit=limits[driver]) if driver in limits else self

    @classmethod
    def from_dict(cls, data: Mapping[str, Any] | None) -> DemoGeometry:
        """Validate demos.yaml's mapping (sections follower, compliant_move, spring, hybrid).

        Raises:
            DemoConfigError: Unknown section or key, a non-number, a sign that is not +-1, a value <= 0.
        """
        data = data or {}
        if not isinstance(data, Mapping):
            raise DemoConfigError(f"demos config must be a mapping, got {type(data).__name__}")
        layout = {
            "follower": {"push_force": "follower_push_force", "push_duration": "follower_push_duration"},
            "compliant_move": {
                "direction": "compliant_direction",
                "speed": "compliant_speed",
                "max_travel": "compliant_max_travel",
            },
            "spring": {"direction": "spring_direction", "push_force": "spring_push_force"},
            "hybrid": {"direction": "hybrid_direction", "speed": "hybrid_speed", "travel": "hybrid_travel"},
            "curved_surface": {"middle": "curved_middle", "length": "curved_length"},
        }
        unknown = set(data) - set(layout) - {"contact_force"}
        if unknown:
            raise DemoConfigError(f"unknown sections {sorted(unknown)}; known: {[*layout, 'contact_force']}")
        values: dict[str, Any] = _contact_force(data.get("contact_force"))
        for section, keys in layout.items():
            got = data.get(section) or {}
            if not isinstance(got, Mapping):
                raise DemoConfigError(f"{section}: expected a mapping, got {got!r}")
            extra = set(got) - set(keys)
            if extra:
                raise DemoConfigError(f"{section}: unknown keys {sorted(extra)}; known: {list(keys)}")
            for key, attr in keys.items():
                if key not in got:
                    continue
                value = got[key]
                name = f"{section}.{key}"
                if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
                    raise DemoConfigError(f"{name}: expected a number, got {value!r}")
                if key == "middle":
                    if abs(value) > 1.0:
                        raise DemoConfigError(f"{name}: expected an angle within 1 rad of the top, got "
                                              f"{value!r}")
                    values[attr] = float(value)
                elif key == "direction":
                    if value not in (-1, 1):
                        raise DemoConfigError(f"{name}: expected -1 or 1, got {value!r}")
                    values[attr] = int(value)
                elif value <= 0:
                    raise DemoConfigError(f"{name}: must be positive, got {value!r}")
                else:
                    values[attr] = float(value)
        return cls(**values)

    def as_dict(self) -> dict[str, dict[str, Any]]:
        """The demos.yaml mapping of these numbers (inverse of :meth:`from_dict`)."""
        out: dict[str, dict[str, Any]] = {}
        if self.contact_force_limit != DemoGeometry.contact_force_limit or self.driver_force_limits:
            out["contact_force"] = {"limit": self.contact_force_limit}  # only when not the thesis's
        if self.driver_force_limits:
            out["contact_force"]["drivers"] = dict(self.driver_force_limits)
        prefixes = {"follower_": "follower", "compliant_": "compliant_move", "spring_": "spring",
                    "hybrid_": "hybrid"}
        curved = {k: v for k, v, default in (("middle", self.curved_middle, 0.0),
                                             ("length", self.curved_length, DemoGeometry.curved_length))
                  if v != default}  # only when set: most arms run 0.3 m centred on the top
        if curved:
            out["curved_surface"] = curved
        for f in fields(self):
            for prefix, section in prefixes.items():
                if f.name.startswith(prefix):
                    out.setdefault(section, {})[f.name[len(prefix):]] = getattr(self, f.name)
        return out


@dataclass(frozen=True)
class Obstacle:
    """The compliant move's obstacle, an axis-aligned box in the base frame [m]."""

    position: tuple[float, float, float]
    size: tuple[float, float, float]

    @property
    def top(self) -> float:
        return self.position[2] + self.size[2] / 2.0

    @property
    def bottom(self) -> float:
        return self.position[2] - self.size[2] / 2.0

    @property
    def top_centre(self) -> tuple[float, float, float]:
        """The centre of its top face [m] (where mujoco_driver's curved parts have their highest point)."""
        return (self.position[0], self.position[1], self.top)

    def covers(self, x: float, y: float, inset: float = 0.0) -> bool:
        """True if (x, y) lies over the box's footprint, at least `inset` inside its edges."""
        return all(
            abs(v - c) <= s / 2.0 - inset
            for v, c, s in zip((x, y), self.position[:2], self.size[:2], strict=True)
        )


def load_geometry(path: str) -> DemoGeometry:
    """Read a demos.yaml.

    Raises:
        DemoConfigError: Unreadable file or bad content (naming the file and the key).
    """
    try:
        with open(path, encoding="utf-8") as handle:
            data = yaml.safe_load(handle)
    except (OSError, yaml.YAMLError) as exc:
        raise DemoConfigError(f"cannot read demos config {path}: {exc}") from exc
    try:
        return DemoGeometry.from_dict(data)
    except DemoConfigError as exc:
        raise DemoConfigError(f"{path}: {exc}") from exc


def load_obstacle(scene_path: str) -> Obstacle | None:
    """The `obstacle` of a scene YAML (sim.yaml), None if it has none; rotated boxes are refused.

    Raises:
        DemoConfigError: Unreadable file or a malformed obstacle.
    """
    try:
        with open(scene_path, encoding="utf-8") as handle:
            data = yaml.safe_load(handle) or {}
    except (OSError, yaml.YAMLError) as exc:
        raise DemoConfigError(f"cannot read scene config {scene_path}: {exc}") from exc
    obs = data.get("obstacle")
    if obs is None:
        return None
    try:
        position = tuple(float(v) for v in obs["position"])
        size = tuple(float(v) for v in obs["size"])
        rpy = tuple(float(v) for v in obs.get("rpy", (0.0, 0.0, 0.0)))
    except (KeyError, TypeError, ValueError) as exc:
        raise DemoConfigError(f"{scene_path}: obstacle needs position and size (3 numbers each)") from exc
    if len(position) != 3 or len(size) != 3:
        raise DemoConfigError(f"{scene_path}: obstacle.position and obstacle.size need 3 numbers each")
    if any(abs(a) > 1e-9 for a in rpy):
        raise DemoConfigError(f"{scene_path}: obstacle.rpy must be 0 for the demos (an axis-aligned box)")
    return Obstacle(position, size)


def tool_radius(description_args: str) -> float:
    """Half the tool's width [m] from a robot package's description.args (make_description's options).

    Raises:
        DemoConfigError: Unreadable file or a tool size that is not numbers.
    """
    import shlex

    try:
        with open(description_args, encoding="utf-8") as handle:
            words = [w for line in handle for w in shlex.split(line, comments=True)]
    except OSError as exc:
        raise DemoConfigError(f"cannot read {description_args}: {exc}") from exc
    shape, size = "cylinder", [0.03, 0.1]  # make_description's defaults
    for i, word in enumerate(words):
        if word == "--tool-shape" and i + 1 < len(words):
            shape = words[i + 1]
        if word == "--tool-size":
            size = []
            for value in words[i + 1:]:
                if value.startswith("--"):
                    break
                try:
                    size.append(float(value))
                except ValueError as exc:
                    raise DemoConfigError(
                        f"{description_args}: --tool-size {value!r} is not a number"
                    ) from exc
    if shape == "box":
        return max(size[0], size[1]) / 2.0
    return float(size[0])


def find_robot_package(robot: str) -> str:
    """Directory of the robot package `<robot>_custom` (found by name with rospkg, no list of robots).

    Raises:
        DemoConfigError: No such package; the message lists the `*_custom` packages that exist.
    """
    import rospkg

    pack = rospkg.RosPack()
    name = f"{robot}_custom"
    try:
        return pack.get_path(name)
    except rospkg.ResourceNotFound:
        known = sorted(p[: -len("_custom")] for p in pack.list() if p.endswith("_custom"))
        raise DemoConfigError(
            f"no robot package {name!r} on ROS_PACKAGE_PATH (build the workspace after adding it: "
            f"make build); robots found: {', '.join(known) or 'none'}"
        ) from None


Motion = tuple[float, float, float]


def demo_motions(geometry: DemoGeometry, approach: float | None = None) -> dict[str, list[Motion]]:
    """Tool-tip displacements [m] (base axes, from the start pose) each demonstration needs room for.

    Args:
        geometry: The demonstrations' numbers.
        approach: Distance of the compliant move before contact; None: its whole max path deviation.

    Returns:
        Per demonstration, the straight-line displacements that must be reachable without a singularity or
        a joint limit: the follower's rise plus a side push, the approach and its backing off, the spring's
        excursion and the hybrid travel (with a 2 cm overrun and the spring on Z).
    """
    # Follower: v = F/b (b = 30) reached at 0.4 m/s^2 (contact_control's acceleration_linear): the push
    # duration bounds the rise, with the deceleration after it on top.
    v = geometry.follower_push_force / 30.0
    rise = v * geometry.follower_push_duration + v * v / (2 * 0.4)
    down = geometry.compliant_max_travel if approach is None else approach + 0.01
    sx, hx = geometry.spring_direction, geometry.hybrid_direction
    travel = geometry.hybrid_travel + 0.02
    return {
        "follower_z": [(0.0, 0.0, rise), (0.01, 0.01, 0.0)],
        "compliant_move_z": [(0.0, 0.0, geometry.compliant_direction * down)],
        "spring_x": [(sx * 0.05, 0.0, 0.0), (-sx * 0.01, 0.0, 0.0)],
        "hybrid": [(hx * travel, 0.0, 0.0), (hx * travel, 0.0, 0.03), (0.0, 0.0, 0.03)],
    }


def preflight(
    geometry: DemoGeometry, tip: Sequence[float], obstacle: Obstacle | None, tool_radius: float = 0.0
) -> dict[str, str]:
    """What this arm's start pose and scene cannot do, per demonstration, in plain words.

    Geometry only (no kinematics: the robot package's checker does the reach, `make check-robot`).

    Args:
        geometry: The demonstrations' numbers.
        tip: Tool tip at the start pose, base frame [m].
        obstacle: The scene's obstacle (None: no obstacle).
        tool_radius: Half the tool's width [m]: the tool must land on the obstacle, not beside it.

    Returns:
        Demonstration name -> reason; the ones not named can run.
    """
    problems: dict[str, str] = {}
    x, y, z = (float(v) for v in tip)
    name = "compliant_move_z"
    if obstacle is None:
        problems[name] = "the scene (sim.yaml) has no obstacle for the compliant move to stop on"
    elif not obstacle.covers(x, y, tool_radius):
        problems[name] = (
            f"the obstacle (centre {obstacle.position[0]:.3f}, {obstacle.position[1]:.3f} m, "
            f"{obstacle.size[0]:.2f} x {obstacle.size[1]:.2f} m) is not under the tool tip at "
            f"({x:.3f}, {y:.3f}) m: the compliant move along Z would miss it"
        )
    else:
        face = obstacle.top if geometry.compliant_direction < 0 else obstacle.bottom
        gap = geometry.compliant_direction * (face - z)
        if gap < MIN_APPROACH:
            problems[name] = (
                f"the obstacle's face is {gap * 100:.1f} cm from the tool tip along the move; it needs at "
                f"least {MIN_APPROACH * 100:.1f} cm of approach (move the obstacle or the start pose)"
            )
        elif gap > geometry.compliant_max_travel - APPROACH_MARGIN:
            problems[name] = (
                f"the obstacle is {gap * 100:.1f} cm away but the move may only travel "
                f"{geometry.compliant_max_travel * 100:.1f} cm (compliant_move.max_travel, minus "
                f"{APPROACH_MARGIN * 100:.0f} cm margin): it would end by its path deviation, not by contact"
            )
    if obstacle is not None:
        # The hybrid move travels along X at the start height (its Z spring only gives way upward).
        x_end = x + geometry.hybrid_direction * geometry.hybrid_travel
        lo, hi = min(x, x_end), max(x, x_end)
        ox, oy = obstacle.position[:2]
        sx, sy = obstacle.size[0] / 2 + tool_radius, obstacle.size[1] / 2 + tool_radius
        crosses = hi >= ox - sx and lo <= ox + sx and abs(y - oy) <= sy
        if crosses and obstacle.bottom - PASSING_CLEARANCE < z < obstacle.top + PASSING_CLEARANCE:
            problems["hybrid"] = (
                f"the hybrid move along {'+' if geometry.hybrid_direction > 0 else '-'}X at z = {z:.3f} m "
                f"would run into the obstacle (top at {obstacle.top:.3f} m)"
            )
    if obstacle is not None and geometry.compliant_direction < 0:
        x_end = x + SURFACE_DIRECTION * SURFACE_TRAVEL
        if not (obstacle.covers(x, y, tool_radius) and obstacle.covers(x_end, y, tool_radius)):
            problems["surface_following"] = (
                f"the tool ({tool_radius * 2000:.0f} mm wide) would not stay on the obstacle's top "
                f"({obstacle.size[0] * 100:.0f} x {obstacle.size[1] * 100:.0f} cm) over the "
                f"{SURFACE_TRAVEL * 100:.0f} cm slide from ({x:.3f}, {y:.3f}) m: it needs a larger block"
            )
    elif obstacle is None or geometry.compliant_direction > 0:
        problems["surface_following"] = "it presses down on the scene's obstacle: there is none below the tip"
    fitted = fit_l(tip, obstacle, tool_radius)
    if isinstance(fitted, str):
        problems["teach_and_replay"] = fitted
    elif geometry.compliant_direction > 0:
        problems["teach_and_replay"] = "it presses down on the scene's obstacle: there is none below the tip"
    if z < 0.03:
        for demo in ("follower_z", "spring_x", "hybrid"):
            problems.setdefault(
                demo, f"the tool tip starts {z * 100:.1f} cm above the table (z = 0): too low"
            )
    return problems


def fit_l(tip: Sequence[float], obstacle: Obstacle | None, tool_radius: float = 0.0,
          legs: tuple[float, float] = (0.10, 0.05)) -> tuple[tuple[float, float], tuple[float, float]] | str:
    """Where the teach-and-replay L goes: its first corner as an offset from the tool tip `tip` and its signed
    legs [m], the `legs` (along X, then Y) scaled down, keeping their ratio, until the L lies centred on the
    obstacle's top with the tool inside its edges by TEACH_MARGIN (the pressed replay slides on it); or why
    it cannot. X runs along SURFACE_DIRECTION (toward the base), Y toward the base's XZ plane."""
    if obstacle is None:
        return "it presses on the scene's obstacle: there is none"
    if not obstacle.covers(float(tip[0]), float(tip[1])):
        return (f"the obstacle (centre {obstacle.position[0]:.3f}, {obstacle.position[1]:.3f} m) is not "
                f"under the tool tip at ({float(tip[0]):.3f}, {float(tip[1]):.3f}) m: the L is taught over "
                "it")
    inset = tool_radius + TEACH_MARGIN
    room = (obstacle.size[0] - 2 * inset, obstacle.size[1] - 2 * inset)
    scale = min(1.0, room[0] / legs[0], room[1] / legs[1])
    lx, ly = scale * legs[0], scale * legs[1]
    if lx < TEACH_MIN_LEG:
        return (f"the obstacle's top ({obstacle.size[0] * 100:.0f} x {obstacle.size[1] * 100:.0f} cm) leaves "
                f"{max(lx, 0.0) * 100:.1f} cm for the L's {legs[0] * 100:.0f} cm leg with the tool "
                f"({tool_radius * 2000:.0f} mm wide) on it; it needs {TEACH_MIN_LEG * 100:.0f} cm: a larger "
                "block")
    dx = float(SURFACE_DIRECTION)
    dy = -1.0 if float(tip[1]) > 0.005 else 1.0  # toward y = 0 (+Y when within 5 mm of it)
    ox, oy = obstacle.position[:2]
    corner = (ox - dx * lx / 2.0 - float(tip[0]), oy - dy * ly / 2.0 - float(tip[1]))
    return corner, (dx * lx, dy * ly)


@dataclass(frozen=True)
class RobotSetup:
    """What run_demos knows of an arm: its demos' geometry, obstacle and tool, and where they came from."""

    geometry: DemoGeometry
    obstacle: Obstacle | None = None
    tool_radius: float = 0.0
    source: str = "thesis-sized defaults"
    checks_scene: bool = False

    def preflight(self, tip: Sequence[float]) -> dict[str, str]:
        """:func:`preflight` with this arm's obstacle and tool."""
        return preflight(self.geometry, tip, self.obstacle, self.tool_radius)


def robot_setup(robot: str = "", demos_config: str = "") -> RobotSetup:
    """The demos' setup of robot package `<robot>_custom` (or a given demos.yaml; defaults when neither).

    Raises:
        DemoConfigError: No such package, or a bad file in it (named).
    """
    if not robot:
        if demos_config:
            return RobotSetup(load_geometry(demos_config), source=demos_config)
        return RobotSetup(DemoGeometry())
    package = find_robot_package(robot)
    path = demos_config or os.path.join(package, DEMOS_FILE)
    if not os.path.isfile(path):
        raise DemoConfigError(
            f"{robot}_custom has no {DEMOS_FILE} (the demonstrations' directions and distances for this "
            "arm); `make robot` writes one, see thesis_demos' README"
        )
    scene = os.path.join(package, SCENE_FILE)
    args = os.path.join(package, "config", "description.args")
    return RobotSetup(
        geometry=load_geometry(path),
        obstacle=load_obstacle(scene) if os.path.isfile(scene) else None,
        tool_radius=tool_radius(args) if os.path.isfile(args) else 0.0,
        source=path,
        checks_scene=os.path.isfile(scene),
    )
