"""Teleop logic: key presses and time in, the twist to publish out (no ROS, no terminal).

A terminal gives no key-release events, only repeated presses while a key is held (after an initial
delay of about 0.5 s, then about 30 per second). So motion is a deadman: the latest motion key sets the
whole twist (one axis at a time, like the original), and the twist stays until `key_timeout` passes without
a motion key; then zero is sent `stop_repeats` times and publishing goes quiet, so that other sources on the
same topic (contact_control) are not overridden by a stream of zeros. The stop key sends zero at once.

Overrun: `key_timeout` must bridge the repeat delay, but only once. When a second press of the same key
arrives while it moves (the terminal's auto-repeat), the deadman shortens to `repeat_timeout`, so releasing a
held key stops the twist within `repeat_timeout` (a few repeat periods), not `key_timeout`. A single tap
moves for `key_timeout`: a tap and the start of a hold look alike until the first repeat.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any, NamedTuple

from compliant_common.errors import StackError
from compliant_common.schema import SchemaError, param, schema_of

from keyboard_publisher.keymap import KEYMAP, Action, Binding

__all__ = [
    "MIN_SPEED_FRACTION",
    "PARAMETERS",
    "ZERO",
    "KeyResult",
    "TeleopSettings",
    "TeleopSettingsError",
    "TeleopState",
    "Twist6",
]

Twist6 = tuple[float, float, float, float, float, float]
ZERO: Twist6 = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0)

# Speed keys multiply or divide by `speed_step`; a multiplicative step never reaches zero, so speeds are
# kept in [MIN_SPEED_FRACTION * max, max].
MIN_SPEED_FRACTION = 0.01

# Typical keyboard auto-repeat delay; a shorter key_timeout stops motion before the first repeat arrives.
TYPICAL_REPEAT_DELAY = 0.5

class TeleopSettingsError(StackError):
    """A parameter has a wrong type or range; `key` names it."""

    def __init__(self, key: str, message: str) -> None:
        super().__init__(f"parameter '~{key}': {message}")
        self.key = key


def _speed_range(limit: str) -> str:
    return f"in [{MIN_SPEED_FRACTION:g} x `~{limit}`, `~{limit}`]"


@dataclass(frozen=True)
class TeleopSettings:
    """Validated parameters of key_to_twist, each declared once here (name, type, default, unit, range, doc).

    Built directly or by :meth:`from_params`; both check every value (`TeleopSettingsError` naming the key).
    """

    topic: str = param(
        "jog_arm_server/delta_jog_cmds", nonempty=True,
        doc="geometry_msgs/TwistStamped output (relative name)",
    )
    frame_id: str = param(
        "", doc="`header.frame_id` of the twists (empty, like the original: the receiver's command frame)"
    )
    key_event_topic: str = param(
        "keyboard_publisher/key_event", nonempty=True, doc="keyboard_publisher/KeyEvent output"
    )
    linear_speed: float = param(
        0.2, unit="m/s", gt=0.0, shown_range=_speed_range("max_linear_speed"),
        doc="initial linear speed (the original's fixed value)",
    )
    max_linear_speed: float = param(0.5, unit="m/s", gt=0.0, doc="upper bound of the linear speed keys")
    angular_speed: float = param(
        0.3, unit="rad/s", gt=0.0, shown_range=_speed_range("max_angular_speed"), doc="initial angular speed"
    )
    max_angular_speed: float = param(1.0, unit="rad/s", gt=0.0, doc="upper bound of the angular speed keys")
    speed_step: float = param(
        1.1, gt=1.0, doc="factor one speed key press multiplies or divides the speed by"
    )
    rate: float = param(50.0, unit="Hz", gt=0.0, le=1000.0, doc="publish rate while moving")
    key_timeout: float = param(
        0.6, unit="s", gt=0.0,
        doc="deadman: zero when no motion key came for this long (must exceed the keyboard's repeat delay, "
        f"else holding a key stutters: a warning at or below {TYPICAL_REPEAT_DELAY} s)",
    )
    repeat_timeout: float = param(
        0.15, unit="s", gt=0.0, shown_range="> 0, <= `~key_timeout`",
        doc="deadman once the key auto-repeats (a few repeat periods, ~33 ms each)",
    )
    stop_repeats: int = param(3, ge=1, doc="zero twists sent after a stop or a timeout, then silence")

    def __post_init__(self) -> None:
        try:
            PARAMETERS.check(PARAMETERS.values_of(self))
        except SchemaError as err:
            raise TeleopSettingsError(err.key, err.message) from None
        if self.repeat_timeout > self.key_timeout:
            raise TeleopSettingsError(
                "repeat_timeout", f"{self.repeat_timeout} s exceeds ~key_timeout ({self.key_timeout} s)"
            )
        for speed, limit in (("linear_speed", "max_linear_speed"), ("angular_speed", "max_angular_speed")):
            value, top = getattr(self, speed), getattr(self, limit)
            if not MIN_SPEED_FRACTION * top <= value <= top:
                raise TeleopSettingsError(
                    speed, f"{value} is outside [{MIN_SPEED_FRACTION * top:g}, {top:g}] (~{limit} = {top:g})"
                )

    @classmethod
    def from_params(cls, params: Mapping[str, Any]) -> tuple[TeleopSettings, list[str]]:
        """Builds settings from a private-parameter dict (`rospy.get_param("~")`).

        Integers are accepted for float parameters (`_rate:=50`).

        Returns:
            The settings and warnings (a key_timeout below the usual repeat delay).

        Raises:
            TeleopSettingsError: an unknown key (naming the closest valid one), a wrong type or range.
        """
        try:
            values = PARAMETERS.load(params, prefix="~")
        except SchemaError as err:
            raise TeleopSettingsError(err.key, err.message) from None
        settings = PARAMETERS.build(cls, values)
        warnings: list[str] = []
        if settings.key_timeout <= TYPICAL_REPEAT_DELAY:
            warnings.append(
                f"~key_timeout {settings.key_timeout} s is not above the usual keyboard repeat delay "
                f"({TYPICAL_REPEAT_DELAY} s): holding a key will stutter"
            )
        return settings, warnings


PARAMETERS = schema_of(TeleopSettings)


class KeyResult(NamedTuple):
    """What one key press did.

    Attributes:
        binding: the key's binding, None for keys the map does not know (ignored).
        publish_now: the command changed (new motion or stop): publish without waiting for the next tick.
        speeds_changed: a speed key changed a speed (show the speeds again).
        released: the previously held key, now considered released because another key came.
    """

    binding: Binding | None
    publish_now: bool
    speeds_changed: bool
    released: str | None


class TeleopState:
    """Turns key presses and times into the twists to publish.

    Args:
        settings: validated parameters.
    """

    def __init__(self, settings: TeleopSettings) -> None:
        self._settings = settings
        self.linear_speed = settings.linear_speed
        self.angular_speed = settings.angular_speed
        self._motion: Binding | None = None
        self._motion_time = 0.0
        self._command: Twist6 = ZERO
        self._zeros_left = 0
        self._held: str | None = None
        self._held_time = 0.0
        self._repeating = False  # the motion key has auto-repeated since it was first pressed

    @property
    def settings(self) -> TeleopSettings:
        return self._settings

    def press(self, key: str, now: float) -> KeyResult:
        """Registers a key press (or a terminal auto-repeat of it) at time `now` (s, monotonic).

        Raises:
            TypeError: `key` is not a string.
            ValueError: `now` is not finite. The state is unchanged in both cases.
        """
        if not isinstance(key, str):
            raise TypeError(f"key must be a string, got {type(key).__name__}")
        if not math.isfinite(now):
            raise ValueError(f"time must be finite, got {now}")
        released = self._held if self._held is not None and self._held != key else None
        binding = KEYMAP.get(key)
        if binding is not None and binding.action is Action.QUIT:
            return KeyResult(binding, False, False, released)
        self._held, self._held_time = key, now
        if binding is None:
            return KeyResult(None, False, False, released)
        if binding.action is Action.MOTION:
            publish_now = binding != self._motion or self._expired(now)
            self._repeating = not publish_now  # the same key again while it moves: the terminal repeats it
            self._motion, self._motion_time = binding, now
            self._update_command()
            return KeyResult(binding, publish_now, False, released)
        if binding.action is Action.STOP:
            self._stop()
            return KeyResult(binding, True, False, released)
        return KeyResult(binding, False, self._step_speed(binding), released)

    def tick(self, now: float) -> Twist6 | None:
        """The twist to publish at this cycle, or None when there is nothing to send (idle).

        Counts the zeros sent after a stop or timeout, so call it once per published message.
        """
        if self._motion is not None:
            if not self._expired(now):
                return self._command
            self._stop()
        if self._zeros_left > 0:
            self._zeros_left -= 1
            return ZERO
        return None

    def command(self, now: float) -> Twist6:
        """The commanded twist at `now` (zero once the deadman expired), without side effects."""
        return self._command if self._motion is not None and not self._expired(now) else ZERO

    def release(self, now: float) -> str | None:
        """The held key, once, when no press of it came within `key_timeout` (a terminal has no releases)."""
        if self._held is not None and now - self._held_time >= self._settings.key_timeout:
            key, self._held = self._held, None
            return key
        return None

    def _expired(self, now: float) -> bool:
        s = self._settings
        return now - self._motion_time >= (s.repeat_timeout if self._repeating else s.key_timeout)

    def _stop(self) -> None:
        self._motion = None
        self._repeating = False
        self._command = ZERO
        self._zeros_left = self._settings.stop_repeats

    def _update_command(self) -> None:
        if self._motion is None:
            self._command = ZERO
            return
        speed = self.linear_speed if self._motion.axis < 3 else self.angular_speed
        twist = [0.0] * 6
        twist[self._motion.axis] = self._motion.sign * speed
        self._command = tuple(twist)  # type: ignore[assignment]

    def _step_speed(self, binding: Binding) -> bool:
        s = self._settings
        factor = s.speed_step if binding.sign > 0 else 1.0 / s.speed_step
        if binding.action is Action.LINEAR_SPEED:
            old = self.linear_speed
            self.linear_speed = _clamp(
                old * factor, MIN_SPEED_FRACTION * s.max_linear_speed, s.max_linear_speed
            )
            changed = self.linear_speed != old
        else:
            old = self.angular_speed
            self.angular_speed = _clamp(
                old * factor, MIN_SPEED_FRACTION * s.max_angular_speed, s.max_angular_speed
            )
            changed = self.angular_speed != old
        self._update_command()
        return changed


def _clamp(value: float, low: float, high: float) -> float:
    return min(max(value, low), high)
