"""The driver node's parameters, read once at start-up into a validated :class:`DriverSettings` (no ROS).

The node passes ``rospy.get_param("~")`` (its private parameters as a dict) and the value of
``/use_sim_time``; every refusal names the key. Units: seconds, Hz-free (periods, not rates).
"""

from __future__ import annotations

import dataclasses
import math
import xml.etree.ElementTree as ET
from collections.abc import Mapping
from dataclasses import dataclass, fields
from typing import Any

from mujoco_driver.config import PerJoint, SceneConfig, load_scene_config

__all__ = ["DriverSettings", "ParamError", "load_scene", "urdf_root_link"]


class ParamError(ValueError):
    """A driver parameter is missing, of the wrong type or out of range; the message names it."""


@dataclass(frozen=True)
class DriverSettings:
    """Everything the node reads besides the URDF (see config/driver.yaml for the documented defaults).

    Attributes:
        scene_config: Path of the scene YAML ("" when ``scene`` is given).
        scene: The scene settings as a mapping (used when ``scene_config`` is "").
        start_pose: Optional override of the scene's start pose (list in URDF joint order or mapping).
        timestep: Override of the scene's physics step [s]; 0 = the scene's. With ``publish_period`` 0 the
            state (wrench, joint_states) goes out every step, so this sets their rate too (1 kHz at 0.001).
        real_time_factor: Simulated seconds per wall-clock second; 0 = as fast as possible.
        publish_clock: Publish rosgraph_msgs/Clock on /clock and stamp everything with simulated time.
        publish_period: Period of joint_states and wrench [s]; 0 = every simulation step.
        joint_states_phase: joint_states (and ~eef_pose) go out this fraction of the publish period after the
            wrench of the same instant (same stamp); 0 = right after it. Keeps the wake-ups they cause in
            other processes out of the way of the wrench-to-command chain.
        eef_pose_period: Period of ~eef_pose [s] (ground truth for plots); 0 = with joint_states.
        command_timeout: Velocity target back to zero this long after the last velocity command [s].
        push_timeout: A ~push_wrench push ends this long after its last message [s].
        max_lag: Largest backlog behind the wall clock caught up without sleeping [s]; more is dropped.
        rtf_period: Window of the ~rtf measurement [s of wall time].
        publish_synchronously: Write to subscribers' sockets in the loop's thread (less CPU; a subscriber
            that stops reading then blocks the simulation) instead of through rospy's writer threads.
        viewer: Open MuJoCo's passive viewer (needs a display).
        viewer_period: Viewer refresh period [s].
        joint_states_topic, wrench_topic, trajectory_command_topic, velocity_command_topic: Topic names.
        ft_frame: header.frame_id of the wrench ("" = the scene's ``links.ft_sensor``).
        base_frame: header.frame_id of eef_pose and the frame of pushes ("" = the URDF root link).
        profile: Driver interface profile to emulate (a name in config/profiles or a YAML path; "" = none):
            it sets the state topics, the wrench frame and rate, and adds the real driver's controllers and
            services (see :mod:`mujoco_driver.profiles`).
        profile_options: The profile's options (a mapping; None = its defaults).
    """

    scene_config: str = ""
    scene: Mapping[str, Any] | None = None
    start_pose: Any = None
    timestep: float = 0.0
    real_time_factor: float = 1.0
    publish_clock: bool = False
    publish_period: float = 0.0
    joint_states_phase: float = 0.5
    eef_pose_period: float = 0.01
    command_timeout: float = 0.1
    push_timeout: float = 0.2
    max_lag: float = 0.1
    rtf_period: float = 2.0
    publish_synchronously: bool = False
    viewer: bool = False
    viewer_period: float = 1.0 / 30.0
    joint_states_topic: str = "joint_states"
    wrench_topic: str = "wrench"
    trajectory_command_topic: str = "arm_controller/command"
    velocity_command_topic: str = "joint_group_velocity_controller/command"
    ft_frame: str = ""
    base_frame: str = ""
    profile: str = ""
    profile_options: Any = None

    @classmethod
    def from_params(cls, params: Mapping[str, Any], use_sim_time: bool = False) -> DriverSettings:
        """Validate the node's private parameters.

        Args:
            params: Private parameters (``rospy.get_param("~")``); missing keys take the defaults.
            use_sim_time: The value of ``/use_sim_time``: the default of ``publish_clock``.

        Raises:
            ParamError: Naming the first bad key.
        """
        values: dict[str, Any] = {}
        for f in fields(cls):
            if f.name not in params:
                continue
            value = params[f.name]
            default = getattr(cls, f.name)
            if f.name in ("scene", "start_pose", "profile_options"):
                values[f.name] = value
            elif isinstance(default, bool):
                if not isinstance(value, bool):
                    raise ParamError(f"~{f.name}: expected true or false, got {value!r}")
                values[f.name] = value
            elif isinstance(default, float):
                if isinstance(value, bool) or not isinstance(value, int | float) or not math.isfinite(value):
                    raise ParamError(f"~{f.name}: expected a finite number, got {value!r}")
                values[f.name] = float(value)
            else:
                if not isinstance(value, str):
                    raise ParamError(f"~{f.name}: expected a string, got {value!r}")
                values[f.name] = value
        values.setdefault("publish_clock", bool(use_sim_time))
        settings = cls(**values)
        settings.validate()
        return settings

    @classmethod
    def unknown_keys(cls, params: Mapping[str, Any]) -> list[str]:
        """Private parameters that are not driver settings (the node warns about them)."""
        return sorted(set(params) - {f.name for f in fields(cls)})

    def validate(self) -> None:
        """Check ranges and cross-constraints.

        Raises:
            ParamError: Naming the first bad key.
        """
        if not self.scene_config and self.scene is None:
            raise ParamError("~scene_config: missing (path of the scene YAML), and no ~scene mapping either")
        if self.scene_config and self.scene is not None:
            raise ParamError("~scene_config and ~scene are both set: give one")
        if self.scene is not None and not isinstance(self.scene, Mapping):
            raise ParamError(f"~scene: expected a mapping, got {type(self.scene).__name__}")
        if self.real_time_factor < 0.0:
            raise ParamError(f"~real_time_factor: must be >= 0 (0: as fast as possible), got "
                             f"{self.real_time_factor}")
        if not self.publish_clock and (self.real_time_factor > 1.0 or self.real_time_factor == 0.0):
            raise ParamError(
                f"~real_time_factor: {self.real_time_factor} runs faster than the wall clock, which needs "
                "simulated time: set ~publish_clock (or /use_sim_time) true"
            )
        if not 0.0 <= self.timestep <= 0.01:
            raise ParamError(f"~timestep: must be in (0, 0.01] s, or 0 for the scene's, got {self.timestep}")
        for key in ("publish_period", "eef_pose_period"):
            if getattr(self, key) < 0.0:
                raise ParamError(f"~{key}: must be >= 0, got {getattr(self, key)}")
        if not 0.0 <= self.joint_states_phase < 1.0:
            raise ParamError("~joint_states_phase: must be in [0, 1) (a fraction of the publish period), "
                             f"got {self.joint_states_phase}")
        for key in ("command_timeout", "push_timeout", "max_lag", "rtf_period", "viewer_period"):
            if not getattr(self, key) > 0.0:
                raise ParamError(f"~{key}: must be > 0, got {getattr(self, key)}")
        topics = ("joint_states_topic", "wrench_topic", "trajectory_command_topic", "velocity_command_topic")
        for key in topics:
            if not getattr(self, key):
                raise ParamError(f"~{key}: must not be empty")
        if self.profile_options is not None and not isinstance(self.profile_options, Mapping):
            raise ParamError(f"~profile_options: expected a mapping (e.g. {{series: e_series}}), got "
                             f"{self.profile_options!r}")
        if self.start_pose is not None and not isinstance(self.start_pose, Mapping | list | tuple):
            raise ParamError(f"~start_pose: expected a list (URDF joint order) or a mapping, got "
                             f"{self.start_pose!r}")

    def eef_pose_every(self, dt: float) -> int:
        """Publications of joint_states between two ~eef_pose (>= 1)."""
        period = max(self.publish_every(dt) * dt, dt)
        return max(1, round(self.eef_pose_period / period))

    def publish_every(self, dt: float) -> int:
        """Simulation steps between two publications (>= 1)."""
        return max(1, round(self.publish_period / dt)) if self.publish_period > 0.0 else 1


def urdf_root_link(urdf_xml: str) -> str:
    """Name of the URDF's root link (the one no joint has as its child).

    Raises:
        ParamError: If the URDF has no single root link.
    """
    try:
        robot = ET.fromstring(urdf_xml)
    except ET.ParseError as exc:
        raise ParamError(f"robot_description: not valid XML: {exc}") from exc
    children = {c.get("link") for joint in robot.iter("joint") for c in joint.findall("child")}
    roots = [link.get("name") for link in robot.findall("link") if link.get("name") not in children]
    if len(roots) != 1:
        raise ParamError(f"robot_description: expected one root link, found {roots}")
    return str(roots[0])


def load_scene(settings: DriverSettings) -> SceneConfig:
    """The scene settings from ``~scene_config`` or ``~scene``, with ``~start_pose`` and ``~timestep``
    applied.

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
    return cfg
