"""The per-axis form and its mapping to a ConfigureForceControl request (pure: no Qt, no rospy).

Mapping per axis (contact_control's README), p = request.cart_impedance_params, c = x, y or z:

===================  ====================================  =====================================
form field           X, Y, Z                               RX, RY, RZ
===================  ====================================  =====================================
law                  direction_control_laws.<x|y|z>.type   direction_control_laws.<rx|ry|rz>.type
damping b            p.damping.translational.c             p.damping.rotational.c
stiffness k          p.stiffness.translational.c           p.stiffness.rotational.c
desired velocity     p.max_cart_vel.set.linear.c           p.max_cart_vel.set.angular.c
max force/torque     p.max_ctrl_force.set.force.c          p.max_ctrl_force.set.torque.c
max path deviation   p.max_path_deviation.translation.c    p.max_path_deviation.rotation.c
===================  ====================================  =====================================

Fields the axis's law does not use are sent as 0. The form's one exceeded action (what happens when a max
force/torque is reached: stop, move_away or gravity_compensation) sets that flag of
`max_ctrl_force.exceeded_action`; contact_control applies it to every axis with a max force/torque.

The same form maps to a compliant_control_msgs/ConfigureLaws request (`write_laws_request`), one AxisLaw per
axis, the action on the axes with a max force/torque; the panel prefers that service when contact_control
offers it, because its answer says why a request was refused.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import asdict, dataclass, replace
from typing import Any

from compliant_common.errors import StackError
from contact_control.request import axis_groups

from manipulator_control_gui.form_config import (
    AXES,
    AXIS_LABELS,
    FIELDS,
    LAW_FIELDS,
    LAWS,
    GuiConfig,
)

__all__ = [
    "EXCEEDED_ACTIONS",
    "LAW_TYPES",
    "AxisForm",
    "FormError",
    "build_laws_request",
    "build_request",
    "check_with_contact_control",
    "default_form",
    "describe_response",
    "form_from_dict",
    "form_to_dict",
    "law_form",
    "preset_form",
    "summarize_form",
    "validate_form",
    "write_laws_request",
    "write_request",
]

#: cartesian_impedance_msgs/ControlLaw TYPE_* of each law.
LAW_TYPES: dict[str, int] = {"none": 0, "follower": 1, "spring": 2, "compliant_move": 3}
#: What the axes with a max force/torque do when it is reached (compliant_control_msgs/AxisLaw ACTION_*), with
#: the text of the panel's choice.
EXCEEDED_ACTIONS: dict[str, tuple[int, str]] = {
    "stop": (0, "stop (the whole move ends, every axis holds)"),
    "move_away": (1, "move away from the contact, then hold"),
    "gravity_compensation": (2, "gravity compensation (the axis follows the hand)"),
}

# cartesian_impedance_msgs/CartesianForceCtrlErrorCodes, with what contact_control means by each.
_SUCCESS = 1
_RESPONSES: dict[int | None, tuple[str, str]] = {  # None (no code known): the default
    99999: (
        "FAILURE",
        "contact control cannot take laws now (a safety stop may be latched: press Reset) "
        "or the request was malformed",
    ),
    -1: ("SET_DOF_FAILED", "an axis has an unknown law"),
    -2: ("SET_CONTROL_FORCE_FAILED", "a max force/torque is invalid or above the controller's global limit"),
    -3: ("SET_FORCE_STIFFNESS_FAILED", "a spring stiffness k is invalid (it must be above 0)"),
    -4: (
        "SET_CARTESIAN_CONTROL_FAILED",
        "a damping, desired velocity or max path deviation is invalid or above the controller's limits",
    ),
}


class FormError(StackError):
    """The form cannot be sent; `axis` and `field` name the culprit ('' when not one field)."""

    def __init__(self, message: str, axis: str = "", field: str = "", code: int | None = None) -> None:
        super().__init__(message)
        self.message = message
        self.axis = axis
        self.field = field
        #: CartesianForceCtrlErrorCodes value when contact_control's own check refused the request.
        self.code = code


@dataclass(frozen=True)
class AxisForm:
    """One row of the form. Units per axis kind: N or N·m, m or rad, m/s or rad/s, N·s/m or N·m·s/rad."""

    law: str = "none"
    damping: float = 0.0
    stiffness: float = 0.0
    velocity: float = 0.0
    max_force: float = 0.0
    max_deviation: float = 0.0


Form = dict[str, AxisForm]


def default_form() -> Form:
    """Every axis `none` (nothing moves)."""
    return {axis: AxisForm() for axis in AXES}


def law_form(config: GuiConfig, axis: str, law: str) -> AxisForm:
    """The row `law` starts with on `axis` (the law's start values from the config)."""
    return AxisForm(law, **config.start_values(law, axis))


def preset_form(config: GuiConfig, name: str) -> Form:
    """The form of preset `name`.

    Raises:
        KeyError: no such preset.
    """
    preset = config.presets[name]
    form = default_form()
    for axis, values in preset.axes.items():
        row = law_form(config, axis, values["law"])
        numbers: dict[str, Any] = {k: float(v) for k, v in values.items() if k != "law"}
        form[axis] = replace(row, **numbers)
    return form


def _label(config: GuiConfig, axis: str, field: str) -> str:
    return config.spec(field, axis).label


def validate_form(config: GuiConfig, form: Mapping[str, AxisForm]) -> None:
    """Checks the form before anything is sent; stops at the first problem.

    Raises:
        FormError: naming the axis and field in plain words.
    """
    missing = [axis for axis in AXES if axis not in form]
    if missing:
        raise FormError(f"The form has no row for axis {', '.join(AXIS_LABELS[a] for a in missing)}.")
    for axis in AXES:
        row = form[axis]
        name = AXIS_LABELS[axis]
        if row.law not in LAWS:
            raise FormError(f"Axis {name}: unknown law '{row.law}'.", axis, "law")
        law_text = config.law_labels[row.law]
        for field in LAW_FIELDS[row.law]:
            value = getattr(row, field)
            spec = config.spec(field, axis)
            what = f"Axis {name} ({law_text}): {spec.label}"
            if not isinstance(value, int | float) or not math.isfinite(value):
                raise FormError(f"{what} is not a number ({value}).", axis, field)
            if value < spec.minimum or value > spec.maximum:
                raise FormError(
                    f"{what} {value:g} {spec.unit} is outside "
                    f"{spec.minimum:g} to {spec.maximum:g} {spec.unit}.",
                    axis,
                    field,
                )
        if row.law in ("follower", "spring") and row.damping <= 0.0:
            unit = config.spec("damping", axis).unit
            raise FormError(
                f"Axis {name} ({law_text}): damping b must be above 0 {unit} "
                "(the law divides the force by b).",
                axis,
                "damping",
            )
        if row.law == "spring" and row.stiffness <= 0.0:
            raise FormError(
                f"Axis {name} (spring): stiffness k must be above 0 {config.spec('stiffness', axis).unit} "
                "(with k = 0 nothing pulls the axis back).",
                axis,
                "stiffness",
            )
        if row.law == "compliant_move":
            if row.velocity == 0.0:
                raise FormError(
                    f"Axis {name} (compliant move): desired velocity must not be 0 "
                    f"{config.spec('velocity', axis).unit}; its sign gives the direction.",
                    axis,
                    "velocity",
                )
            if row.max_force == 0.0 and row.max_deviation == 0.0:
                raise FormError(
                    f"Axis {name} (compliant move): set a max force/torque or a max path deviation above 0, "
                    "or the move would never end.",
                    axis,
                    "max_deviation",
                )


def _check_action(action: str) -> None:
    if action not in EXCEEDED_ACTIONS:
        known = ", ".join(EXCEEDED_ACTIONS)
        raise FormError(f"Unknown action on max force/torque '{action}'; known: {known}.")


def write_request(form: Mapping[str, AxisForm], req: Any, action: str = "stop") -> Any:
    """Writes every axis of `form` into `req` (ConfigureForceControlRequest or same-shaped tree); returns it.

    Fields the axis's law does not use are written as 0, so nothing stale is sent.

    Args:
        form: the six rows.
        req: the request to fill.
        action: a key of EXCEEDED_ACTIONS; its flag of max_ctrl_force.exceeded_action is set, the others not.

    Raises:
        FormError: an unknown action.
    """
    _check_action(action)
    p = req.cart_impedance_params
    for axis in AXES:
        row = form[axis]
        used = LAW_FIELDS[row.law]
        values = [getattr(row, f) if f in used else 0.0 for f in FIELDS]
        groups = axis_groups(p, AXES.index(axis))
        component = axis[-1]
        for group, value in zip(groups, values, strict=True):
            setattr(group, component, float(value))
        getattr(req.direction_control_laws, axis).type = LAW_TYPES[row.law]
    flags = p.max_ctrl_force.exceeded_action
    for name in EXCEEDED_ACTIONS:
        setattr(flags, name, name == action)
    return req


def write_laws_request(form: Mapping[str, AxisForm], req: Any, action: str = "stop") -> Any:
    """Writes `form` into a ConfigureLaws request (or same-shaped tree: fields x .. rz); returns it.

    Fields the axis's law does not use are written as 0; `action` goes to the axes with a max force/torque
    (the others keep stop: they have nothing to exceed), as contact_control maps the original service's one
    action.

    Raises:
        FormError: an unknown action.
    """
    _check_action(action)
    code = EXCEEDED_ACTIONS[action][0]
    for axis in AXES:
        row, target = form[axis], getattr(req, axis)
        used = LAW_FIELDS[row.law]
        damping, stiffness, velocity, max_force, max_deviation = (
            float(getattr(row, f)) if f in used else 0.0 for f in FIELDS
        )
        target.law = LAW_TYPES[row.law]
        target.damping, target.stiffness, target.velocity = damping, stiffness, velocity
        target.force_limit, target.max_travel = max_force, max_deviation
        target.exceeded_action = code if row.law != "none" and max_force > 0.0 else 0
    return req


def check_with_contact_control(req: Any, laws: bool = False) -> bool:
    """Runs contact_control's own request validation (the node's check, without its velocity/force limits).

    Args:
        req: the request.
        laws: it is a ConfigureLaws request (else ConfigureForceControl).

    Returns:
        True if the check ran, False if contact_control is not importable (then only the form was checked).

    Raises:
        FormError: contact_control would refuse the request; `code` is its CartesianForceCtrlErrorCodes value.
    """
    try:
        from contact_control.request import RequestError, validate_laws_request, validate_request
    except ImportError:
        return False
    try:
        (validate_laws_request if laws else validate_request)(req)
    except RequestError as err:
        axis = getattr(err, "axis", "")
        raise FormError(
            f"contact_control would refuse this: {err}", axis, "", getattr(err, "code", None)
        ) from err
    return True


def build_request(
    config: GuiConfig, form: Mapping[str, AxisForm], req: Any = None, action: str = "stop"
) -> Any:
    """Checks the form, maps it to a request and has contact_control check the request.

    Args:
        config: the form description (ranges).
        form: the six rows.
        req: the request object to fill; None for a new ConfigureForceControlRequest.
        action: what the axes with a max force/torque do when it is reached (a key of EXCEEDED_ACTIONS).

    Raises:
        FormError: the form or the request is invalid; nothing should be sent.
    """
    validate_form(config, form)
    if req is None:
        from cartesian_impedance_msgs.srv import ConfigureForceControlRequest

        req = ConfigureForceControlRequest()
    write_request(form, req, action)
    check_with_contact_control(req)
    return req


def build_laws_request(
    config: GuiConfig, form: Mapping[str, AxisForm], req: Any = None, action: str = "stop"
) -> Any:
    """As `build_request`, for compliant_control_msgs/ConfigureLaws (None: a new ConfigureLawsRequest).

    Raises:
        FormError: the form or the request is invalid; nothing should be sent.
    """
    validate_form(config, form)
    if req is None:
        from compliant_control_msgs.srv import ConfigureLawsRequest

        req = ConfigureLawsRequest()
    write_laws_request(form, req, action)
    check_with_contact_control(req, laws=True)
    return req


def summarize_form(config: GuiConfig, form: Mapping[str, AxisForm]) -> str:
    """'X compliant move, Z spring' or 'all axes none'."""
    active = [f"{AXIS_LABELS[a]} {config.law_labels[form[a].law]}" for a in AXES if form[a].law != "none"]
    return ", ".join(active) if active else "all axes none (nothing moves)"


def describe_response(success: bool, code: int | None = None, reason: str = "") -> str:
    """A service answer in plain words.

    Args:
        success: the response's `success`.
        code: a CartesianForceCtrlErrorCodes value when one is known. The response's `error` field cannot
            carry one on the wire (that message has constants only, as in the original), so the reply
            alone gives None; contact_control_node reports the code and reason on its status topic.
        reason: contact_control's own words for the refusal, when known.
    """
    if success:
        return "Applied: contact control accepted the laws."
    if code == _SUCCESS:
        return "Not applied: contact control answered 'not successful' with code SUCCESS."
    name, meaning = _RESPONSES.get(code, ("unknown code", "contact control refused the request"))
    if reason:
        return f"Refused: {reason} (error {name}, {code})." if code is not None else f"Refused: {reason}."
    if code is None:
        return (
            "Refused: contact control did not accept the laws. They passed the same checks it makes, so "
            "it is one of its own limits (max_velocity, global_max_force/torque) or a latched safety "
            "stop (press Reset); its status line and log say which."
        )
    return f"Refused: {meaning} (error {name}, {code})."


def form_to_dict(form: Mapping[str, AxisForm]) -> dict[str, dict[str, Any]]:
    """Plain data (for saving the GUI's state)."""
    return {axis: asdict(form[axis]) for axis in AXES}


def form_from_dict(data: Mapping[str, Mapping[str, Any]]) -> Form:
    """The inverse of `form_to_dict`; unknown axes, laws or fields are dropped (old saves stay loadable)."""
    form = default_form()
    for axis in AXES:
        values = data.get(axis)
        if not isinstance(values, Mapping) or values.get("law") not in LAWS:
            continue
        numbers = {}
        for field in FIELDS:
            value = values.get(field, 0.0)
            if isinstance(value, int | float) and not isinstance(value, bool):
                numbers[field] = float(value)
        form[axis] = AxisForm(values["law"], **numbers)
    return form
