"""The driver node's parameters, read once at start-up into a validated :class:`DriverSettings` (no ROS).

The node passes ``rospy.get_param("~")`` (its private parameters as a dict) and the value of
``/use_sim_time``; every refusal names the key. Units: seconds, Hz-free (periods, not rates).
"""

from __future__ import annotations

import dataclasses
import xml.etree.ElementTree as ET
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np
from compliant_common.errors import StackError
from compliant_common.schema import Param, SchemaError, param, schema_of

from mujoco_driver.config import Hand, Hole, PerJoint, SceneConfig, Surface, load_scene_config
from mujoco_driver.fixtures import free_hand, hole_offset

__all__ = ["PARAMETERS", "DriverParamError", "DriverSettings", "load_scene", "urdf_root_link"]


class DriverParamError(StackError):
    """A driver parameter is missing, of the wrong type or out of range; the message names it."""


def _pos(default: float, unit: str, doc: str) -> Any:
    return param(default, unit=unit, gt=0.0, doc=doc)


def _topic(default: str, doc: str) -> Any:
    return param(default, nonempty=True, doc=doc)


@dataclass(frozen=True)
class DriverSettings:
    """Everything the node reads besides the URDF, each parameter declared once here (name, type, default,
    unit, range, doc); config/driver.yaml holds the values the launch files load."""

    scene_config: str = param(
        "", shown_default="(required)", doc="path of the scene YAML; or give the mapping itself as `~scene`"
    )
    scene: Mapping[str, Any] | None = param(
        None, type="mapping", optional=True,
        doc="the scene settings themselves (when `scene_config` is empty)",
    )
    start_pose: Any = param(
        None, shown_default="the scene's", unit="rad", shown_range="a list or a mapping",
        doc="override: list in URDF joint order (the arm's joints: held ones excluded) or `{joint: angle}`; "
        "`~reset` returns here", type="any",
    )
    timestep: float = param(
        0.0, unit="s", ge=0.0, le=0.01, shown_default="the scene's",
        doc="override of the scene's physics step (0 = the scene's); with `publish_period` 0 it is also the "
        "state's period (0.001: wrench and `joint_states` at 1 kHz)",
    )
    real_time_factor: float = param(
        1.0, ge=0.0,
        doc="simulated s per wall s; above 1, or 0 (as fast as possible), only with `publish_clock`",
    )
    publish_clock: bool = param(
        False, shown_default="`/use_sim_time`",
        doc="publish rosgraph_msgs/Clock on `/clock` and stamp everything with simulated time",
    )
    publish_period: float = param(
        0.0, unit="s", ge=0.0, doc="period of `joint_states`, `wrench`, `~eef_pose`; 0 = every step"
    )
    joint_states_phase: float = param(
        0.5, unit="publish periods", ge=0.0, lt=1.0,
        doc="`joint_states` and `~eef_pose` go out this long after the wrench of the same instant (same "
        "stamp): the wake-ups they cause (robot_state_publisher, jog_arm's joint callback) then do not "
        "compete with the wrench-to-command chain on a 2-core machine (wrench-to-command p50 0.36 → 0.25 ms "
        "here). 0 = right after the wrench. Running as fast as possible it is 0",
    )
    eef_pose_period: float = param(
        0.01, unit="s", ge=0.0, doc="period of `~eef_pose` (ground truth for plots); 0 = with `joint_states`"
    )
    fixture: str = param(
        "none", choices=("none", "clear", "hole", "hand", "free_hand", "tilted", "cylinder", "sphere"),
        doc="clear: no block (a cell's arms meeting over the tables); hole: a plate with a square, chamfered "
        "hole on the obstacle block, for a square peg tool; hand: "
        "a person's hand (ISO/TS 15066: 0.6 kg, 75 N/mm) lying on the block; free_hand: that hand held in "
        "the air in the block's place, free to move when struck; tilted: the block turned by "
        "`surface_tilt` about the base's y axis, a sloping top; cylinder (axis along y), sphere: a curved "
        "part in the block's place, its top at the block's top centre (README, Fixtures)",
    )
    surface_tilt: float = param(
        0.2618, unit="rad", gt=0.0, le=0.7, doc="with `fixture` tilted: the block's turn about y (15 degrees)"
    )
    surface_radius: float = param(
        0.0, unit="m", ge=0.0, le=2.0,
        doc="the cylinder's or sphere's radius; 0: the fixture's own (cylinder 0.25 m, sphere 0.3 m)"
    )
    surface_offset: tuple[float, ...] = param(
        (0.0, 0.0, 0.0), type="floats", length=3, unit="m",
        doc="the curved part's (or the tilted block's) offset from its nominal place (dx, dy, dz), which a "
        "task is not told",
    )
    surface_seed: int = param(
        -1, ge=-1, doc=">= 0: the surface's offset drawn from this seed instead (each of dx, dy, dz within "
        "10 mm)"
    )
    surface_friction: float = param(
        0.3, unit="", gt=0.0, le=2.0, doc="sliding friction of the tilted, cylinder or sphere fixture with "
        "the tool (a guess: a polishing pad on metal)"
    )
    hole_offset: tuple[float, ...] = param(
        (0.0, 0.0, 0.0), type="floats", length=3, unit="m, m, rad",
        doc="the hole's offset from the block's top centre (dx, dy, yaw), which a task is not told",
    )
    hole_seed: int = param(
        -1, ge=-1, doc=">= 0: the offset drawn from this seed instead (within 4 mm and 2 degrees of nominal)"
    )
    hole_tilt: tuple[float, ...] = param(
        (0.0, 0.0), type="floats", length=2, unit="rad, rad",
        doc="the hole's axis tilted about its own x, then y axis through the plate top's centre (roll, "
        "pitch; at most 0.1 rad), which a task is not told",
    )
    hole_clearance: float = param(0.0004, unit="m", gt=0.0, le=0.01, doc="hole width minus the peg's")
    hole_chamfer: float = param(0.001, unit="m", ge=0.0, le=0.005,
                                doc="the hole's 45-degree chamfer (0: none)")
    hole_depth: float = param(0.02, unit="m", gt=0.0, le=0.1, doc="the hole's depth")
    peg_width: float = param(0.01, unit="m", gt=0.0, le=0.05, doc="the square peg's width (the tool's)")
    command_timeout: float = _pos(
        0.1, "s", "velocity watchdog: the velocity target goes back to zero this long after the last command"
    )
    push_timeout: float = _pos(0.2, "s", "end of a `~push_wrench` push after its last message")
    max_lag: float = _pos(
        0.1, "s", "backlog behind the wall clock caught up without sleeping; a longer one is dropped (logged)"
    )
    lockstep_lead: float = param(
        0.01, unit="s", ge=0.0, le=0.1,
        doc="while the arm is driven (a nonzero velocity command), step at most this far in simulated time "
        "past the newest velocity command and the newest echo, then wait for the stack: a stalled "
        "controller pauses the simulation instead of letting the arm drive on (README, Lockstep). 0: off",
    )
    lockstep_wait: float = _pos(
        1.0, "s", "longest wait (wall time the driver was awake: a freeze of the whole machine is not the "
        "stack's silence) for a silent stack; then the simulation runs on until it speaks again, and "
        "`command_timeout` stops the arm"
    )
    lockstep_echo_topic: str = param(
        "",
        doc="a topic whose messages carry, first, a std_msgs/Header stamped with the wrench the controller "
        "answered (contact_control's `~contact_wrench` when jog_arm runs apart); empty: commands only",
    )
    rtf_period: float = _pos(2.0, "s", "window of `~rtf` (wall time)")
    publish_synchronously: bool = param(
        False,
        doc="write subscribers' sockets in the loop: ~40 % less CPU and ~0.3 ms less wrench latency (no "
        "sender thread), but a subscriber that stops reading (`rostopic echo | less`) then freezes the "
        "simulation once its socket buffer is full. `sim_stack.launch` turns it on (arg "
        "`publish_synchronously`)",
    )
    viewer: bool = param(
        False,
        doc="MuJoCo's passive viewer (only when `DISPLAY` or `WAYLAND_DISPLAY` is set and the display "
        "answers; otherwise a warning with the reason and headless); mouse perturbations work, pushes go on "
        "while it is open",
    )
    viewer_period: float = _pos(1.0 / 30.0, "s", "viewer refresh period")
    joint_states_topic: str = _topic("joint_states", "sensor_msgs/JointState output")
    wrench_topic: str = _topic("wrench", "geometry_msgs/WrenchStamped output (F/T sensor frame)")
    trajectory_command_topic: str = _topic(
        "arm_controller/command", "trajectory_msgs/JointTrajectory command input"
    )
    velocity_command_topic: str = _topic(
        "joint_group_velocity_controller/command", "std_msgs/Float64MultiArray velocity command input"
    )
    ft_frame: str = param("", shown_default="`links.ft_sensor`", doc="`frame_id` of the wrench")
    base_frame: str = param(
        "", shown_default="URDF root link", doc="`frame_id` of `~eef_pose`, frame of pushes"
    )
    profile: str = param(
        "",
        doc="emulate a real driver (see *Driver emulation*): a name in `config/profiles` or a YAML path; it "
        "sets the state topics, the wrench frame and rate, and adds the real driver's controllers and "
        "services",
    )
    profile_options: Mapping[str, Any] | None = param(
        None, type="mapping", optional=True, doc="the profile's options (e.g. `{series: e_series}`)"
    )

    @classmethod
    def from_params(cls, params: Mapping[str, Any], use_sim_time: bool = False) -> DriverSettings:
        """Validate the node's private parameters.

        Args:
            params: Private parameters (``rospy.get_param("~")``); missing keys take the defaults.
            use_sim_time: The value of ``/use_sim_time``: the default of ``publish_clock``.

        Raises:
            DriverParamError: Naming the first bad key, or an unknown key and the closest valid one.
        """
        try:
            values = PARAMETERS.load(params, prefix="~")
        except SchemaError as err:
            raise DriverParamError(err.named("~")) from None
        values.setdefault("publish_clock", bool(use_sim_time))  # the key is the attribute's name
        settings = PARAMETERS.build(cls, values)
        settings.validate()
        return settings

    def validate(self) -> None:
        """Check the relations between parameters (each one's own range is in its declaration).

        Raises:
            DriverParamError: Naming the first bad key.
        """
        if not self.scene_config and self.scene is None:
            raise DriverParamError(
                "~scene_config: missing (path of the scene YAML), and no ~scene mapping either")
        if self.scene_config and self.scene is not None:
            raise DriverParamError("~scene_config and ~scene are both set: give one")
        if not self.publish_clock and (self.real_time_factor > 1.0 or self.real_time_factor == 0.0):
            raise DriverParamError(
                f"~real_time_factor: {self.real_time_factor} runs faster than the wall clock, which needs "
                "simulated time: set ~publish_clock (or /use_sim_time) true"
            )
        if self.start_pose is not None and not isinstance(self.start_pose, Mapping | list | tuple):
            raise DriverParamError(f"~start_pose: expected a list (URDF joint order) or a mapping, got "
                             f"{self.start_pose!r}")

    def eef_pose_every(self, dt: float) -> int:
        """Publications of joint_states between two ~eef_pose (>= 1)."""
        period = max(self.publish_every(dt) * dt, dt)
        return max(1, round(self.eef_pose_period / period))

    def publish_every(self, dt: float) -> int:
        """Simulation steps between two publications (>= 1)."""
        return max(1, round(self.publish_period / dt)) if self.publish_period > 0.0 else 1


#: The declared parameters; `robot_description` is read by the node itself (private, else the shared one).
PARAMETERS = schema_of(DriverSettings, extra=[Param(
    "robot_description", "str", "", shown_default="(the shared one)",
    doc="private override of the URDF (emulated_robot.launch sets it)",
)])


def urdf_root_link(urdf_xml: str) -> str:
    """Name of the URDF's root link (the one no joint has as its child).

    Raises:
        DriverParamError: If the URDF has no single root link.
    """
    try:
        robot = ET.fromstring(urdf_xml)
    except ET.ParseError as exc:
        raise DriverParamError(f"robot_description: not valid XML: {exc}") from exc
    children = {c.get("link") for joint in robot.iter("joint") for c in joint.findall("child")}
    roots = [link.get("name") for link in robot.findall("link") if link.get("name") not in children]
    if len(roots) != 1:
        raise DriverParamError(f"robot_description: expected one root link, found {roots}")
    return str(roots[0])


# contact_tasks' peg_in_hole demonstration: the hole within 4 mm and 2 degrees of its nominal pose.
HOLE_SPREAD = 0.004  # [m]
HOLE_YAW_SPREAD = 0.035  # [rad]
HOLE_TILT_MAX = 0.1  # [rad] the 120 mm plate's edge then 6 mm off the block's top


# The finishing fixtures: each kind's default radius [m] and how far its place is from nominal.
SURFACE_RADIUS = {"tilted": 0.0, "cylinder": 0.25, "sphere": 0.3}
SURFACE_SPREAD = 0.01  # [m] each of dx, dy, dz with surface_seed


def _with_surface(cfg: SceneConfig, settings: DriverSettings) -> SceneConfig:
    """The scene with the `tilted`, `cylinder` or `sphere` fixture (config.Surface)."""
    kind = settings.fixture
    if cfg.obstacle is None:
        raise DriverParamError(f"~fixture {kind}: the scene has no obstacle block to stand for the part")
    offset = tuple(settings.surface_offset)
    if settings.surface_seed >= 0:
        offset = tuple(float(x) for x in np.random.default_rng(settings.surface_seed).uniform(
            -SURFACE_SPREAD, SURFACE_SPREAD, 3))
    block = cfg.obstacle
    if kind == "tilted":
        roll, pitch, yaw = block.rpy
        x, y, z = (a + b for a, b in zip(block.position, offset, strict=True))
        block = dataclasses.replace(block, position=(x, y, z), rpy=(roll, pitch + settings.surface_tilt, yaw))
        surface = Surface("plane", friction=settings.surface_friction)
    else:
        radius = settings.surface_radius or SURFACE_RADIUS[kind]
        surface = Surface(kind, radius, offset, settings.surface_friction)  # type: ignore[arg-type]
    return dataclasses.replace(cfg, obstacle=block, surface=surface)


def load_scene(settings: DriverSettings) -> SceneConfig:
    """The scene settings from ``~scene_config`` or ``~scene``, with ``~start_pose`` applied.

    Raises:
        ConfigError: On an unreadable file or a bad setting.
    """
    if settings.scene_config:
        cfg = load_scene_config(settings.scene_config)
    else:
        cfg = SceneConfig.from_dict(settings.scene or {})
    if settings.start_pose is not None:
        cfg = dataclasses.replace(cfg, start_pose=PerJoint.parse(settings.start_pose, "~start_pose"))
    if settings.timestep > 0.0:
        cfg = dataclasses.replace(cfg, timestep=settings.timestep)
    if settings.fixture == "hole":
        if cfg.obstacle is None:
            raise DriverParamError("~fixture hole: the scene has no obstacle block to put the plate on")
        offset = tuple(settings.hole_offset)
        if settings.hole_seed >= 0:
            offset = hole_offset(settings.hole_seed, HOLE_SPREAD, HOLE_YAW_SPREAD)
        if any(abs(a) > HOLE_TILT_MAX for a in settings.hole_tilt):
            raise DriverParamError(f"~hole_tilt {list(settings.hole_tilt)}: each angle at most "
                                   f"{HOLE_TILT_MAX} rad (the plate would leave the block)")
        hole = Hole(peg=settings.peg_width, clearance=settings.hole_clearance, depth=settings.hole_depth,
                    chamfer=settings.hole_chamfer, offset=offset,  # type: ignore[arg-type]
                    tilt=tuple(settings.hole_tilt))  # type: ignore[arg-type]
        cfg = dataclasses.replace(cfg, hole=hole)
    if settings.fixture in SURFACE_RADIUS:
        cfg = _with_surface(cfg, settings)
    if settings.fixture == "clear":
        cfg = dataclasses.replace(cfg, obstacle=None)
    if settings.fixture == "hand":
        if cfg.obstacle is None:
            raise DriverParamError("~fixture hand: the scene has no obstacle block to lay the hand on")
        cfg = dataclasses.replace(cfg, hand=Hand())
    if settings.fixture == "free_hand":
        if cfg.obstacle is None:
            raise DriverParamError("~fixture free_hand: the scene has no obstacle block to put the hand in "
                                   "place of")
        cfg = dataclasses.replace(cfg, obstacle=None, hand=free_hand(cfg.obstacle))
    return cfg
