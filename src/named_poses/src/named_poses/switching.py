"""Which ros_control controllers to switch so a move can use the trajectory controller (no ROS).

On a UR behind ur_robot_driver jog_arm streams to joint_group_vel_controller while the trajectory controller
named_poses needs is stopped; both claim the same joints, so only one runs. A named-pose move switches the
trajectory controller on, stopping the running controllers that claim any of its joints, and afterwards
switches back (see the README, Controller switching).
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from dataclasses import dataclass

from compliant_common.errors import StackError

__all__ = ["Controller", "Switch", "SwitchError", "controller_of", "plan_switch"]


class SwitchError(StackError):
    """The trajectory controller cannot be switched on (unknown, or nothing to switch with)."""


@dataclass(frozen=True)
class Controller:
    """One entry of controller_manager/list_controllers."""

    name: str
    state: str  # running, stopped, initialized, ...
    resources: frozenset[str]  # the joints it claims


@dataclass(frozen=True)
class Switch:
    """A switch_controller request, and the one that undoes it."""

    start: tuple[str, ...]
    stop: tuple[str, ...]

    def undo(self) -> Switch:
        return Switch(start=self.stop, stop=self.start)


def controller_of(topic: str) -> str:
    """The controller whose command topic `topic` is (`.../<controller>/command`), or "" if it is none."""
    parts = [p for p in topic.split("/") if p]
    return parts[-2] if len(parts) >= 2 and parts[-1] == "command" else ""


def plan_switch(controllers: Iterable[Controller], wanted: str) -> Switch | None:
    """The switch that makes `wanted` run, None if it already runs.

    Raises:
        SwitchError: `wanted` is not loaded.
    """
    listing: Sequence[Controller] = list(controllers)
    by_name = {c.name: c for c in listing}
    target = by_name.get(wanted)
    if target is None:
        known = sorted(by_name)
        raise SwitchError(f"controller {wanted!r} is not loaded in the controller manager (loaded: {known})")
    if target.state == "running":
        return None
    stop = tuple(
        c.name for c in listing
        if c.name != wanted and c.state == "running" and c.resources & target.resources
    )
    return Switch(start=(wanted,), stop=stop)
