"""The driver a generated robot package's hardware files are written for: generic, or a mujoco_driver profile.

Pure (no ROS). `make robot ... DRIVER=<profile>` names a driver interface profile of mujoco_driver
(`config/profiles/<name>.yaml`, or a YAML path): the same file mujoco_driver's emulated_robot.launch speaks
with, so the hardware files the generator writes are run against that emulation unchanged. Everything
driver-specific comes from the profile's data (no driver name appears here):

* topics: `joint_states_topic`, `wrench.topic`; the wrench's frame (`wrench.frame`) and the URDF links its
  tf needs (`wrench.frame_link`, `tf`: checked against the description);
* the wrench convention: `wrench.sign` (-1: contact_control flips the sensor axes), `wrench.model`
  (`payload_compensated`, `external_estimate`: the driver already removed the tool's weight, so
  contact_control compensates no tool: `tool_mass` 0), the rate (`publish_rate`: filter design, state
  timeout);
* the controllers (`controllers`, with their `command` and `initial_state`):
    - jog_arm commands a `velocity` controller when the driver has one (a stream of joint velocities,
      jog_arm's `velocity_array`: no trajectory timing on the wire), else a `trajectory` controller; among
      those, a running one first, then the profile's order;
    - named_poses sends its trajectories to a `trajectory` controller, a running one first;
    - when jog_arm's controller is not `running` at start-up, the user switches it on through
      `<controller_manager>/switch_controller`, stopping the running controllers that command the joints
      (two would claim the same joints: a resource conflict).

Without a profile (`DRIVER` empty) the interface is the generic ros_control one of mujoco_driver's own
node: `joint_states`, `wrench` in frame `ft_sensor` (the raw sensor: the tool's weight included), a
joint_trajectory_controller on `arm_controller/command`.
"""

from __future__ import annotations

import math
from collections.abc import Collection
from dataclasses import dataclass

from compliant_common.errors import StackError
from mujoco_driver.profiles import (
    DriverProfile,
    ProfileError,
    ProtectiveStopSpec,
    ReflexSpec,
    known_profiles,
    load_profile,
    profile_path,
)

__all__ = ["GENERIC", "GENERIC_TRAJECTORY_TOPIC", "DriverError", "DriverInterface", "driver_interface"]

GENERIC_TRAJECTORY_TOPIC = "arm_controller/command"  # mujoco_driver's own JointTrajectory input
# jog_arm's joint-state timeout: this many of the driver's state periods, at least MIN_STATE_TIMEOUT [s].
STATE_TIMEOUT_PERIODS = 5.0
MIN_STATE_TIMEOUT = 0.1


class DriverError(StackError):
    """An unknown or unusable driver profile (the message names it and the known profiles)."""


@dataclass(frozen=True)
class DriverInterface:
    """What the hardware files say about the driver.

    Attributes:
        profile: `DRIVER` as given: a profile name or YAML path ("" = generic).
        driver: The real driver's name (the profile's `driver`; "" = generic).
        joint_states_topic: sensor_msgs/JointState topic.
        wrench_topic: geometry_msgs/WrenchStamped topic.
        wrench_frame: Its header.frame_id.
        wrench_model: `sensor` (the tool's weight included), `payload_compensated` or `external_estimate`.
        wrench_sign: +1: the wrench on the tool; -1: its opposite.
        zero_service: std_srvs/Trigger that zeroes the wrench ("" = none).
        rate: The driver's state and wrench rate [Hz] (0 = not known: generic).
        tf: The driver's tf transforms as (parent, child) frames.
        links: URDF links the profile needs in the description.
        controller_manager: Namespace of the controller manager ("" = none).
        jog_controller: The controller jog_arm commands ("" = generic).
        jog_command: `velocity` or `trajectory`.
        jog_initial_state: `running`, `stopped` or `initialized` at the driver's start.
        stop_for_jog: Controllers to stop when switching jog_controller on.
        trajectory_controller: The controller named_poses sends trajectories to ("" = generic).
        trajectory_initial_state: Its state at the driver's start.
        protective_stop: The driver's safety stop and recovery (None = none; jog_arm's `robot_stop`).
        reflex: The driver's collision reflex and recovery (None = none; jog_arm's `robot_stop`).
    """

    profile: str = ""
    driver: str = ""
    joint_states_topic: str = "joint_states"
    wrench_topic: str = "wrench"
    wrench_frame: str = "ft_sensor"
    wrench_model: str = "sensor"
    wrench_sign: int = 1
    zero_service: str = ""
    rate: float = 0.0
    tf: tuple[tuple[str, str], ...] = ()
    links: frozenset[str] = frozenset()
    controller_manager: str = ""
    jog_controller: str = ""
    jog_command: str = "trajectory"
    jog_initial_state: str = "running"
    stop_for_jog: tuple[str, ...] = ()
    trajectory_controller: str = ""
    trajectory_initial_state: str = "running"
    protective_stop: ProtectiveStopSpec | None = None
    reflex: ReflexSpec | None = None

    @property
    def generic(self) -> bool:
        return not self.profile

    @property
    def jog_topic(self) -> str:
        """jog_arm's `cmd_out_topic`."""
        return f"{self.jog_controller}/command" if self.jog_controller else GENERIC_TRAJECTORY_TOPIC

    @property
    def jog_command_type(self) -> str:
        """jog_arm's `command_out_type`."""
        return "velocity_array" if self.jog_command == "velocity" else "trajectory"

    @property
    def trajectory_topic(self) -> str:
        """named_poses' `trajectory_topic`."""
        if not self.trajectory_controller:
            return GENERIC_TRAJECTORY_TOPIC
        return f"{self.trajectory_controller}/command"

    @property
    def switch_needed(self) -> bool:
        """Whether the user must switch jog_arm's controller on before jogging."""
        return self.jog_initial_state != "running"

    @property
    def payload_compensated(self) -> bool:
        """Whether the driver's wrench already excludes the tool's weight (contact_control: tool_mass 0)."""
        return self.wrench_model != "sensor"

    @property
    def state_timeout(self) -> float:
        """jog_arm's `joint_state_timeout` [s]: STATE_TIMEOUT_PERIODS state periods, 0.1 s at least."""
        if self.rate <= 0.0:
            return MIN_STATE_TIMEOUT
        return max(MIN_STATE_TIMEOUT, math.ceil(STATE_TIMEOUT_PERIODS / self.rate * 100.0 - 1e-9) / 100.0)

    def summary(self) -> str:
        """One line for the generator's log."""
        if self.generic:
            return (f"hardware files for a generic ros_control driver: {self.joint_states_topic}, "
                    f"{self.wrench_topic} in {self.wrench_frame}, jog_arm and named_poses on "
                    f"{self.jog_topic}")
        switch = (f" (switched on by the user, stopping {', '.join(self.stop_for_jog) or 'nothing'})"
                  if self.switch_needed else "")
        return (
            f"hardware files for {self.driver} (profile {self.profile}): {self.joint_states_topic}, "
            f"{self.wrench_topic} in {self.wrench_frame} ({self.wrench_model}, sign {self.wrench_sign:+d}, "
            f"{self.rate:g} Hz), jog_arm on {self.jog_topic}{switch}, named_poses on {self.trajectory_topic}"
        )

    def missing_links(self, links: Collection[str]) -> list[str]:
        """The profile's frames the description lacks, in words (empty: none)."""
        problems = [f"link {link!r} (the profile's tf or wrench.frame_link)"
                    for link in sorted(self.links) if link not in links]
        published = {child for _, child in self.tf}
        if not self.generic and self.wrench_frame not in published and self.wrench_frame not in links:
            problems.append(f"wrench frame {self.wrench_frame!r} (neither a link nor on the profile's tf)")
        return problems


GENERIC = DriverInterface()


def _pick(profile: DriverProfile, command: str) -> tuple[str, str]:
    """(name, initial state) of the first running controller with this command, else the first one."""
    candidates = [c for c in profile.controllers if c.command == command]
    candidates.sort(key=lambda c: c.initial_state != "running")  # stable: the profile's order otherwise
    return (candidates[0].name, candidates[0].initial_state) if candidates else ("", "")


def driver_interface(driver: str) -> DriverInterface:
    """The interface of `DRIVER`: a mujoco_driver profile name or YAML path ("" = generic).

    Raises:
        DriverError: Unknown profile (naming the known ones), an invalid profile, or one without a
            controller jog_arm or named_poses could command.
    """
    if not driver:
        return GENERIC
    try:
        profile_path(driver)
    except ProfileError:
        raise DriverError(
            f"DRIVER={driver}: no such mujoco_driver profile; known profiles: {', '.join(known_profiles())}, "
            "or a profile YAML path"
        ) from None
    try:
        profile = load_profile(driver)
    except ProfileError as exc:
        raise DriverError(f"DRIVER={driver}: invalid mujoco_driver profile: {exc}") from None
    jog, jog_state = _pick(profile, "velocity")
    command = "velocity"
    if not jog:
        jog, jog_state = _pick(profile, "trajectory")
        command = "trajectory"
    trajectory, trajectory_state = _pick(profile, "trajectory")
    if not jog or not trajectory:
        commands = {c.name: c.command for c in profile.controllers}
        raise DriverError(
            f"DRIVER={driver}: the profile needs a controller with `command: trajectory` (named_poses; also "
            f"jog_arm's when there is no `command: velocity` one); its controllers: {commands}"
        )
    stop = tuple(c.name for c in profile.controllers
                 if c.command != "none" and c.initial_state == "running" and c.name != jog)
    return DriverInterface(
        profile=driver,
        driver=profile.driver,
        joint_states_topic=profile.joint_states_topic,
        wrench_topic=profile.wrench.topic,
        wrench_frame=profile.wrench.frame,
        wrench_model=profile.wrench.model,
        wrench_sign=int(profile.wrench.sign),
        zero_service=profile.wrench.zero_service,
        rate=profile.publish_rate,
        tf=tuple((t.parent, t.child) for t in profile.tf),
        links=frozenset(profile.links()),
        controller_manager=profile.controller_manager,
        jog_controller=jog,
        jog_command=command,
        jog_initial_state=jog_state,
        stop_for_jog=stop if jog_state != "running" else (),
        protective_stop=profile.protective_stop,
        reflex=profile.reflex,
        trajectory_controller=trajectory,
        trajectory_initial_state=trajectory_state,
    )
