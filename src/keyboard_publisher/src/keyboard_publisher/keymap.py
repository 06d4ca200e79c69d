"""The key map: the one place that says what each key does, and its rendering as help text.

Keys are strings: a printable character as itself (`"w"`, `" "`), control characters as themselves
(`"\\x03"` is Ctrl-C), and special keys by name (`"up"`, `"page_up"`, `"escape"`; see `terminal`).
Axes are indices into a twist `(vx, vy, vz, wx, wy, wz)`, linear in m/s and angular in rad/s.

The original keys keep their meaning (`w`/`s` linear x +/-, `d`/`a` linear y +/-, `x` stop). The rotation
keys sit on the right hand in the same shape as the translation keys on the left: `i`/`k` like `w`/`s`
(about x), `l`/`j` like `d`/`a` (about y), `u`/`o` like `q`/`e` (about z).
"""

from __future__ import annotations

from dataclasses import dataclass
from enum import Enum
from types import MappingProxyType

__all__ = [
    "AXIS_NAMES",
    "KEYMAP",
    "Action",
    "Binding",
    "key_code",
    "key_label",
    "render_help",
    "render_speeds",
]

AXIS_NAMES = ("linear x", "linear y", "linear z", "angular x", "angular y", "angular z")


class Action(Enum):
    """What a key does."""

    MOTION = "motion"  # move along/about `axis` in direction `sign` at the current speed
    STOP = "stop"  # zero twist at once
    LINEAR_SPEED = "linear speed"  # raise (`sign` +1) or lower (-1) the linear speed one step
    ANGULAR_SPEED = "angular speed"  # raise or lower the angular speed one step
    QUIT = "quit"  # leave the node (the terminal is in raw mode, so Ctrl-C arrives as a key)


@dataclass(frozen=True)
class Binding:
    """One key's meaning.

    Attributes:
        action: what the key does.
        axis: twist index 0..5 for `Action.MOTION`, -1 otherwise.
        sign: +1 or -1 (direction of motion or of the speed step), 0 for stop and quit.
    """

    action: Action
    axis: int = -1
    sign: int = 0


def _motion(axis: int, sign: int) -> Binding:
    return Binding(Action.MOTION, axis, sign)


KEYMAP: MappingProxyType[str, Binding] = MappingProxyType(
    {
        "w": _motion(0, +1),
        "s": _motion(0, -1),
        "d": _motion(1, +1),
        "a": _motion(1, -1),
        "r": _motion(2, +1),
        "f": _motion(2, -1),
        "i": _motion(3, +1),
        "k": _motion(3, -1),
        "l": _motion(4, +1),
        "j": _motion(4, -1),
        "u": _motion(5, +1),
        "o": _motion(5, -1),
        # Arrows duplicate the planar keys (right = +y like `d`, as in the original's key map).
        "up": _motion(0, +1),
        "down": _motion(0, -1),
        "right": _motion(1, +1),
        "left": _motion(1, -1),
        "page_up": _motion(2, +1),
        "page_down": _motion(2, -1),
        "x": Binding(Action.STOP),
        " ": Binding(Action.STOP),
        "t": Binding(Action.LINEAR_SPEED, sign=+1),
        "g": Binding(Action.LINEAR_SPEED, sign=-1),
        "y": Binding(Action.ANGULAR_SPEED, sign=+1),
        "h": Binding(Action.ANGULAR_SPEED, sign=-1),
        "\x03": Binding(Action.QUIT),  # Ctrl-C
        "\x04": Binding(Action.QUIT),  # Ctrl-D
    }
)

# X11 keysyms of the named keys, so KeyEvent.keyCode means what it meant for the original's X11 publisher.
_KEYSYMS = {
    "escape": 0xFF1B,
    "enter": 0xFF0D,
    "backspace": 0xFF08,
    "tab": 0xFF09,
    "home": 0xFF50,
    "left": 0xFF51,
    "up": 0xFF52,
    "right": 0xFF53,
    "down": 0xFF54,
    "page_up": 0xFF55,
    "page_down": 0xFF56,
    "end": 0xFF57,
    "insert": 0xFF63,
    "delete": 0xFFFF,
}

_LABELS = {" ": "space", "\x03": "Ctrl-C", "\x04": "Ctrl-D", "page_up": "PgUp", "page_down": "PgDn"}


def key_code(key: str) -> int:
    """The KeyEvent `keyCode` of a key: its X11 keysym.

    For characters that is the Unicode code point (X11 keysyms equal it for Latin-1); named keys use the
    X11 values (`up` is 0xFF52). Keys with no 16-bit code give 0.
    """
    if key in _KEYSYMS:
        return _KEYSYMS[key]
    if len(key) == 1 and ord(key) <= 0xFFFF:
        return ord(key)
    return 0


def key_label(key: str) -> str:
    """How a key is written in help text (`"space"`, `"Ctrl-C"`, `"up"`, `"w"`)."""
    return _LABELS.get(key, key)


def _keys_for(action: Action, axis: int = -1, sign: int = 0) -> list[str]:
    wanted = Binding(action, axis, sign)
    return [key_label(key) for key, binding in KEYMAP.items() if binding == wanted]


def render_speeds(linear: float, angular: float, max_linear: float, max_angular: float) -> str:
    """One line with the current and maximum speeds."""
    return (
        f"speed: linear {linear:.3f} m/s (max {max_linear:.3f}), "
        f"angular {angular:.3f} rad/s (max {max_angular:.3f})"
    )


def render_help(
    linear: float,
    angular: float,
    max_linear: float,
    max_angular: float,
    key_timeout: float,
    speed_step: float,
) -> str:
    """The key map and current speeds as a text table, built from `KEYMAP` so it cannot disagree with it.

    Args:
        linear: current linear speed, m/s.
        angular: current angular speed, rad/s.
        max_linear: its bound, m/s.
        max_angular: its bound, rad/s.
        key_timeout: deadman time, s.
        speed_step: the factor one speed key press multiplies or divides the speed by.
    """
    lines = [
        "Keyboard jogging. Hold a key to move; motion stops "
        f"{key_timeout:.2f} s after the last key press.",
        f"{'':12s}{'+':14s}{'-'}",
    ]
    for axis, name in enumerate(AXIS_NAMES):
        plus = " ".join(_keys_for(Action.MOTION, axis, +1))
        minus = " ".join(_keys_for(Action.MOTION, axis, -1))
        lines.append(f"{name:12s}{plus:14s}{minus}")
    step = f"factor {speed_step:g} per press"
    lines += [
        f"{'stop':12s}{' or '.join(_keys_for(Action.STOP))}",
        f"{'lin. speed':12s}{' '.join(_keys_for(Action.LINEAR_SPEED, sign=+1))} faster, "
        f"{' '.join(_keys_for(Action.LINEAR_SPEED, sign=-1))} slower ({step})",
        f"{'ang. speed':12s}{' '.join(_keys_for(Action.ANGULAR_SPEED, sign=+1))} faster, "
        f"{' '.join(_keys_for(Action.ANGULAR_SPEED, sign=-1))} slower ({step})",
        f"{'quit':12s}{' or '.join(_keys_for(Action.QUIT))}",
        render_speeds(linear, angular, max_linear, max_angular),
    ]
    return "\n".join(lines)
