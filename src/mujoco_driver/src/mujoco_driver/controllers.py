"""An emulated ros_control controller manager: which controller runs, and so whose commands move the arm.

Pure (no ROS): the node serves ``controller_manager/list_controllers`` and ``switch_controller`` from it and
asks :meth:`ControllerManager.accepts` before passing a command on. The behaviour follows ros_control
(Noetic) as the real drivers use it:

* states are ``running``, ``stopped`` and ``initialized`` (loaded, never started: what
  ``spawner --stopped`` leaves);
* a switch is one step: stop the listed controllers, then start the listed ones; with ``STRICT`` an unknown
  name, starting a running controller or stopping one that is not running fails the whole switch and
  changes nothing; with ``BEST_EFFORT`` those names are skipped;
* two running controllers may not claim the same joint through a command interface (ros_control's resource
  conflict check): such a switch fails in either strictness.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

from compliant_common.errors import StackError

__all__ = ["BEST_EFFORT", "STRICT", "ControllerError", "ControllerManager", "ControllerSpec", "SwitchResult"]

BEST_EFFORT = 1  # controller_manager_msgs/SwitchController constants
STRICT = 2
_STATES = ("running", "stopped", "initialized")


class ControllerError(StackError):
    """A controller list in a profile is invalid (the message names the controller and the key)."""


@dataclass(frozen=True)
class ControllerSpec:
    """One loaded controller.

    Attributes:
        name: Its name (and namespace of its command topic).
        type: The plugin type list_controllers reports (``joint_state_controller/JointStateController``).
        command: What its topic carries: ``velocity`` (std_msgs/Float64MultiArray), ``trajectory``
            (trajectory_msgs/JointTrajectory) or ``none`` (a state controller).
        hardware_interface: Interface its resources are claimed through ("" for none).
        initial_state: ``running``, ``stopped`` or ``initialized`` at start-up.
    """

    name: str
    type: str
    command: str = "none"
    hardware_interface: str = ""
    initial_state: str = "running"

    @property
    def claims_joints(self) -> bool:
        """Whether it claims the arm's joints: command controllers do, state controllers do not."""
        return self.command != "none"

    @classmethod
    def from_dict(cls, data: Mapping[str, Any]) -> ControllerSpec:
        """Build from a profile's mapping.

        Raises:
            ControllerError: On a missing name, unknown key or bad value.
        """
        if not isinstance(data, Mapping) or not data.get("name"):
            raise ControllerError(f"controller entry {data!r}: needs a 'name'")
        name = str(data["name"])
        known = {"name", "type", "command", "hardware_interface", "initial_state"}
        unknown = set(data) - known
        if unknown:
            raise ControllerError(f"controller {name!r}: unknown keys {sorted(unknown)} "
                                  f"(known: {sorted(known)})")
        spec = cls(
            name=name,
            type=str(data.get("type", "")),
            command=str(data.get("command", "none")),
            hardware_interface=str(data.get("hardware_interface", "")),
            initial_state=str(data.get("initial_state", "running")),
        )
        if spec.command not in ("velocity", "trajectory", "none"):
            raise ControllerError(f"controller {name!r}: command must be velocity, trajectory or none, "
                                  f"got {spec.command!r}")
        if spec.initial_state not in _STATES:
            raise ControllerError(f"controller {name!r}: initial_state must be one of {_STATES}, "
                                  f"got {spec.initial_state!r}")
        return spec


@dataclass
class SwitchResult:
    """Outcome of :meth:`ControllerManager.switch`: ``ok`` and why not (for the log)."""

    ok: bool
    message: str = ""
    started: list[str] = field(default_factory=list)
    stopped: list[str] = field(default_factory=list)


class ControllerManager:
    """Controller states and switching, as ros_control's controller manager.

    Args:
        controllers: The loaded controllers (names unique).
        joints: The arm's joint names (the resources command controllers claim).

    Raises:
        ControllerError: On duplicate names, or two command controllers running at start-up that claim the
            same joints.
    """

    def __init__(self, controllers: Sequence[ControllerSpec], joints: Sequence[str]) -> None:
        names = [c.name for c in controllers]
        duplicates = sorted({n for n in names if names.count(n) > 1})
        if duplicates:
            raise ControllerError(f"controllers listed twice: {duplicates}")
        self._specs = {c.name: c for c in controllers}
        self._state = {c.name: c.initial_state for c in controllers}
        self.joints = tuple(joints)
        clash = self._conflict(self.running())
        if clash:
            raise ControllerError(f"controllers running at start-up claim the same joints: {clash}")

    @property
    def specs(self) -> tuple[ControllerSpec, ...]:
        """The loaded controllers, in profile order."""
        return tuple(self._specs.values())

    def state(self, name: str) -> str:
        """State of a loaded controller (KeyError for an unknown one)."""
        return self._state[name]

    def running(self) -> list[str]:
        """Names of the running controllers, in profile order."""
        return [n for n, s in self._state.items() if s == "running"]

    def accepts(self, name: str) -> bool:
        """Whether commands to controller ``name`` move the arm now (it is loaded and running)."""
        return self._state.get(name) == "running"

    def listing(self) -> list[tuple[ControllerSpec, str, list[str]]]:
        """(spec, state, claimed joints) per controller, for list_controllers."""
        return [(spec, self._state[spec.name], list(self.joints) if spec.claims_joints else [])
                for spec in self._specs.values()]

    def _conflict(self, running: Iterable[str]) -> list[str]:
        claimers = [n for n in running if self._specs[n].claims_joints]
        return claimers if len(claimers) > 1 else []

    def switch(self, start: Sequence[str], stop: Sequence[str], strictness: int) -> SwitchResult:
        """Stop ``stop``, then start ``start``, in one step.

        Args:
            start: Controllers to start.
            stop: Controllers to stop.
            strictness: :data:`STRICT` or :data:`BEST_EFFORT` (0, as ros_control, means BEST_EFFORT).

        Returns:
            The result; on failure nothing changed.
        """
        if strictness == 0:
            strictness = BEST_EFFORT
        if strictness not in (BEST_EFFORT, STRICT):
            return SwitchResult(False, f"strictness must be BEST_EFFORT (1) or STRICT (2), got {strictness}")
        start_ok, stop_ok, problems = [], [], []
        for name in stop:
            if name not in self._specs:
                problems.append(f"cannot stop {name!r}: not loaded")
            elif self._state[name] != "running":
                problems.append(f"cannot stop {name!r}: it is {self._state[name]}")
            else:
                stop_ok.append(name)
        for name in start:
            if name not in self._specs:
                problems.append(f"cannot start {name!r}: not loaded")
            elif self._state[name] == "running" and name not in stop_ok:
                problems.append(f"cannot start {name!r}: already running")
            else:
                start_ok.append(name)
        if problems and strictness == STRICT:
            return SwitchResult(False, "; ".join(problems))
        after = [n for n in self.running() if n not in stop_ok] + start_ok
        clash = self._conflict(dict.fromkeys(after))
        if clash:
            return SwitchResult(False, f"resource conflict: {clash} would all command the joints "
                                       f"{list(self.joints)}; stop one in the same switch")
        for name in stop_ok:
            self._state[name] = "stopped"
        for name in start_ok:
            self._state[name] = "running"
        return SwitchResult(True, "; ".join(problems), started=start_ok, stopped=stop_ok)
