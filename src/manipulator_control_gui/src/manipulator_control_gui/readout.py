"""Texts of the live readout from a compliant_control_msgs/ContactControlStatus (pure, duck-typed).

The numbers equal the message constants (AxisState END_*, ContactControlStatus SAFETY_*,
ControlLaw TYPE_*); a test checks that they still do. A code this panel does not know is shown with the
name the node sends beside it (`safety_name`, `end_condition_name`), so a newer node still reads in words.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from typing import Any

from manipulator_control_gui.form_config import AXES, is_angular

__all__ = [
    "END_TEXT",
    "LAW_TEXT",
    "REACTION_TEXT",
    "SAFETY_TEXT",
    "AxisReadout",
    "Readout",
    "readout_from_status",
    "refusal_in_status",
]

END_TEXT: dict[int, str] = {
    0: "",
    1: "ended: force/torque limit",
    2: "ended: max path deviation",
    3: "ended: force jump",
    4: "ended: no F/T data",
    5: "ended: stopped",
}
SAFETY_TEXT: dict[int, str] = {
    0: "ok",
    1: "invalid wrench (NaN): holding still",
    2: "force over the global limit: holding still until Reset",
    3: "no recent wrench: holding still",
    4: "missing transform: holding still",
    5: "zeroing the sensor: keep the tool free and still",
}
LAW_TEXT: dict[int, str] = {0: "none", 1: "follower", 2: "spring", 3: "compliant move"}
#: AxisState.exceeded_action while the axis carries it out (AxisState.reacting) after the move ended.
REACTION_TEXT: dict[str, str] = {
    "move_away": "moving away from the contact",
    "gravity_compensation": "hand-guiding (gravity compensation)",
}


@dataclass(frozen=True)
class AxisReadout:
    """One axis: the texts of its readout cells."""

    force: str
    velocity: str
    travel: str
    end: str


@dataclass(frozen=True)
class Readout:
    """Everything the readout shows."""

    wrench: str
    velocity: str
    state: str
    axes: dict[str, AxisReadout]
    ok: bool


def _vec(v: Any) -> tuple[float, float, float]:
    return (float(v.x), float(v.y), float(v.z))


def readout_from_status(status: Any) -> Readout:
    """The readout texts of one status message."""
    f, t = _vec(status.wrench.force), _vec(status.wrench.torque)
    lin, ang = _vec(status.velocity.linear), _vec(status.velocity.angular)
    wrench = "F [{:+.2f} {:+.2f} {:+.2f}] N   T [{:+.2f} {:+.2f} {:+.2f}] N·m".format(*f, *t)
    velocity = "v [{:+.3f} {:+.3f} {:+.3f}] m/s   ω [{:+.3f} {:+.3f} {:+.3f}] rad/s".format(*lin, *ang)
    safety = int(status.safety)
    reacting = bool(getattr(status, "reacting", False))
    parts = ["move running" if status.move_active else "move ended, exceeded action running" if reacting
             else "no move"]
    safety_name = getattr(status, "safety_name", "") or f"code {safety}"
    parts.append("safety " + SAFETY_TEXT.get(safety, safety_name))
    if status.message:
        parts.append(str(status.message))
    axes: dict[str, AxisReadout] = {}
    for state in status.axes:
        name = str(state.axis).lower()
        if name not in AXES:
            continue
        angular = is_angular(name)
        units = ("N·m", "rad/s", "rad") if angular else ("N", "m/s", "m")
        code = int(state.end_condition)
        end = END_TEXT.get(code, f"ended: {getattr(state, 'end_condition_name', '') or f'code {code}'}")
        if code == 0 and status.move_active and int(state.law) != 0:
            end = "running"
        if getattr(state, "reacting", False):
            action = str(getattr(state, "exceeded_action", ""))
            end = " · ".join(p for p in (end, REACTION_TEXT.get(action, action)) if p)
        axes[name] = AxisReadout(
            force=f"{state.force:+.2f} {units[0]}",
            velocity=f"{state.velocity:+.3f} {units[1]}",
            travel=f"{state.travel:+.3f} {units[2]}",
            end=end,
        )
    return Readout(wrench, velocity, " · ".join(parts), axes, safety == 0)


# contact_control_node appends this note to its status message after it refuses a request (and clears it on
# the next accepted one): the service reply itself cannot carry the reason. It is the message's last part, and
# the reason may itself contain "; " ("...; X reads cart_impedance_params...; got 0.3"): read to the end.
_REFUSAL = re.compile(r"(?:^|; )last request refused \(code (-?\d+)\): (.+)$", re.S)


def refusal_in_status(message: str) -> tuple[int, str] | None:
    """(error code, reason) of the last refused request, if the status message reports one."""
    match = _REFUSAL.search(message.strip())
    return (int(match.group(1)), match.group(2)) if match else None
