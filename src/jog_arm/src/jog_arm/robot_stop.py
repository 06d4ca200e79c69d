"""The robot's own stops, as its driver reports them (no ROS; the README's *Robot stops*).

A robot package names, under jog_arm's ``robot_stop`` parameter, the driver topics that say whether the
arm takes commands (a UR's safety mode and program state, ...) and the services that recover it. A value
outside a topic's ``running`` values is a stop: jog_arm holds, refuses commands and says why until it is
asked to recover (``~recover``) and the driver reports running again. A stop seen before the driver ever
reported running (a robot not started yet) clears by itself once it does.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass

from jog_arm.settings import SettingsError

__all__ = ["RecoveryStep", "RobotStop", "StopWatch", "parse_robot_stop"]


@dataclass(frozen=True)
class StopWatch:
    """One driver topic: its message type, the field read and the values that mean "taking commands"."""

    topic: str
    type: str
    field: str
    running: tuple[object, ...]


@dataclass(frozen=True)
class RecoveryStep:
    """One step of the driver's recovery: a std_srvs/Trigger service, or an action with an empty goal
    (``action_type``: its ``package/NameAction``)."""

    name: str
    action_type: str = ""  # "": a std_srvs/Trigger service


def parse_robot_stop(params: object, prefix: str = "") -> tuple[tuple[StopWatch, ...],
                                                               tuple[RecoveryStep, ...]]:
    """The watched topics and the recovery steps (called in order) from the ``robot_stop`` parameter ({} or
    None: nothing watched). A step is a service name (std_srvs/Trigger) or ``{action: name, type:
    package/NameAction}`` (an action whose goal is empty).

    Raises:
        SettingsError: Naming the bad key.
    """
    where = f"{prefix}robot_stop"
    if not params:
        return (), ()
    if not isinstance(params, Mapping) or set(params) - {"watch", "recover"}:
        raise SettingsError(f"{where}: expected a mapping with keys watch and recover, got {params!r}")
    watches = []
    for i, entry in enumerate(params.get("watch") or []):
        at = f"{where}.watch[{i}]"
        keys = ("topic", "type", "field", "running")
        if not isinstance(entry, Mapping) or set(entry) != set(keys):
            raise SettingsError(f"{at}: expected exactly the keys {list(keys)}, got {entry!r}")
        if not all(isinstance(entry[k], str) and entry[k] for k in keys[:3]) or "/" not in entry["type"]:
            raise SettingsError(f"{at}: topic, type (package/Message) and field must be names, got {entry!r}")
        running = entry["running"]
        if not isinstance(running, list) or not running:
            raise SettingsError(f"{at}.running: expected a non-empty list of values, got {running!r}")
        watches.append(StopWatch(entry["topic"], entry["type"], entry["field"], tuple(running)))
    recover = params.get("recover") or []
    if not isinstance(recover, list):
        raise SettingsError(f"{where}.recover: expected a list of steps, got {recover!r}")
    steps = [_recovery_step(entry, f"{where}.recover[{i}]") for i, entry in enumerate(recover)]
    if steps and not watches:
        raise SettingsError(f"{where}.recover: needs watch entries (nothing would say the robot stopped)")
    return tuple(watches), tuple(steps)


def _recovery_step(entry: object, where: str) -> RecoveryStep:
    if isinstance(entry, str) and entry:
        return RecoveryStep(entry)
    if isinstance(entry, Mapping) and set(entry) == {"action", "type"} and isinstance(entry["action"], str) \
            and entry["action"] and isinstance(entry["type"], str) and entry["type"].endswith("Action") \
            and "/" in entry["type"]:
        return RecoveryStep(entry["action"], entry["type"])
    raise SettingsError(f"{where}: expected a std_srvs/Trigger service name or {{action: name, type: "
                        f"package/NameAction}}, got {entry!r}")


class RobotStop:
    """The latest value of each watched topic and the latched stop.

    Args:
        watches: What to watch (:func:`parse_robot_stop`).
    """

    def __init__(self, watches: Sequence[StopWatch]) -> None:
        self.watches = tuple(watches)
        self._values: list[object] = [None] * len(self.watches)  # None: not heard yet
        self._names: list[str] = [""] * len(self.watches)
        self._ever_running = False
        self._latched_since_start = False  # the stop was there before the driver ever reported running
        self._cause = len(self.watches)  # the watch the reason names
        #: Why the robot stopped ("" = it did not, or it recovered).
        self.reason = ""

    def update(self, index: int, value: object, name: str = "") -> bool:
        """Topic ``index`` reads ``value`` (``name``: its constant's name, if any); True when this makes a
        stop, or names it better: a watch listed earlier stops too (a package lists the cause, e.g. the
        safety mode, before its consequences, e.g. the program stopped, which may arrive first)."""
        self._values[index], self._names[index] = value, name
        if self.driver_running():
            self._ever_running = True
            if self.reason and self._latched_since_start:
                self.reason, self._cause = "", len(self.watches)  # not started yet; now it is
            return False
        watch = self.watches[index]
        if value in watch.running or (self.reason and index >= self._cause):
            return False
        shown = f"{name} ({value})" if name else repr(value)
        if not self.reason:
            self._latched_since_start = not self._ever_running
        self.reason, self._cause = f"the robot stopped: {watch.topic} reads {shown}", index
        return True

    def driver_running(self) -> bool:
        """Whether every watched topic heard so far reads a running value."""
        return all(v is None or v in w.running for v, w in zip(self._values, self.watches, strict=True))

    def state(self) -> str:
        """What the driver reports now, e.g. 'ur_hardware_interface/safety_mode: NORMAL (1); ...'."""
        parts = []
        for watch, value, name in zip(self.watches, self._values, self._names, strict=True):
            shown = "not heard yet" if value is None else (f"{name} ({value})" if name else repr(value))
            parts.append(f"{watch.topic}: {shown}")
        return "; ".join(parts)

    def recover(self) -> tuple[bool, str]:
        """Clear the stop if the driver runs again: (cleared, why not / what was cleared)."""
        if not self.reason:
            return True, "the robot was not stopped"
        if not self.driver_running():
            return False, f"the driver still reports a stop ({self.state()})"
        was, self.reason, self._cause = self.reason, "", len(self.watches)
        return True, f"recovered from: {was}"
