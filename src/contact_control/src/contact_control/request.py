"""ConfigureForceControl request <-> six per-axis laws, with validation (no ROS import; duck-typed).

Mapping per axis (the package README's table), with p = req.cart_impedance_params, c the axis letter:

=============  ====================================  =======================================
               X, Y, Z                                RX, RY, RZ
=============  ====================================  =======================================
law            req.direction_control_laws.<x|y|z>    req.direction_control_laws.<rx|ry|rz>
b              p.damping.translational.c              p.damping.rotational.c
k              p.stiffness.translational.c            p.stiffness.rotational.c
V_desired      p.max_cart_vel.set.linear.c            p.max_cart_vel.set.angular.c
force limit    p.max_ctrl_force.set.force.c           p.max_ctrl_force.set.torque.c
max travel     p.max_path_deviation.translation.c     p.max_path_deviation.rotation.c
=============  ====================================  =======================================

Only the fields an axis's law uses are read and checked. The request has no d_offset field: it is 0.
`req.cart_force_control` and `null_space_params` are ignored. The GUI imports `validate_request`,
`fill_request` and `empty_request` from here.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from types import SimpleNamespace
from typing import TYPE_CHECKING, TypeAlias, TypeVar

from compliant_common.errors import StackError

from contact_control.axes import (
    AXES,
    EXCEEDED_ACTION_NAMES,
    EXCEEDED_GRAVITY_COMPENSATION,
    EXCEEDED_STOP,
    LAW_COMPLIANT_MOVE,
    LAW_FOLLOWER,
    LAW_FORCE_TRACKING,
    LAW_NAMES,
    LAW_NONE,
    LAW_PATH,
    LAW_SPRING,
)
from contact_control.laws import AxisLaw
from contact_control.params import ContactControlSettings

if TYPE_CHECKING:  # for annotations only: this module imports no ROS package
    from cartesian_impedance_msgs.msg import SetCartesianImpedance
    from cartesian_impedance_msgs.srv import ConfigureForceControlRequest
    from compliant_control_msgs.srv import ConfigureLawsRequest
    from geometry_msgs.msg import Vector3

#: A ConfigureForceControl request: the genpy message, or the same attribute tree of SimpleNamespaces
#: (`empty_request`).
ForceControlRequest: TypeAlias = "ConfigureForceControlRequest | SimpleNamespace"
#: A compliant_control_msgs/ConfigureLaws request: the genpy message or `empty_laws_request()`.
LawsRequest: TypeAlias = "ConfigureLawsRequest | SimpleNamespace"
_ImpedanceParams: TypeAlias = "SetCartesianImpedance | SimpleNamespace"
_Vector3: TypeAlias = "Vector3 | SimpleNamespace"
_ForceRequestT = TypeVar("_ForceRequestT", bound=ForceControlRequest)
_LawsRequestT = TypeVar("_LawsRequestT", bound=LawsRequest)

__all__ = [
    "CODE_NAMES",
    "FAILURE",
    "SET_CARTESIAN_CONTROL_FAILED",
    "SET_CONTROL_FORCE_FAILED",
    "SET_DOF_FAILED",
    "SET_FORCE_STIFFNESS_FAILED",
    "SUCCESS",
    "ForceControlRequest",
    "LawsRequest",
    "RequestError",
    "RequestLimits",
    "axis_groups",
    "empty_laws_request",
    "empty_request",
    "fill_laws_request",
    "fill_request",
    "force_control_fields",
    "laws_fields",
    "validate_laws_request",
    "validate_request",
]

# cartesian_impedance_msgs/CartesianForceCtrlErrorCodes
SUCCESS = 1
FAILURE = 99999  # malformed request object, or the controller cannot take laws now (safety latched)
SET_DOF_FAILED = -1  # unknown law type on an axis
SET_CONTROL_FORCE_FAILED = -2  # force/torque limit NaN, negative, above the global limit; exceeded action
SET_FORCE_STIFFNESS_FAILED = -3  # spring stiffness k <= 0 or NaN
SET_CARTESIAN_CONTROL_FAILED = -4  # damping, desired velocity or max travel invalid
CODE_NAMES = {
    SUCCESS: "SUCCESS",
    FAILURE: "FAILURE",
    SET_DOF_FAILED: "SET_DOF_FAILED",
    SET_CONTROL_FORCE_FAILED: "SET_CONTROL_FORCE_FAILED",
    SET_FORCE_STIFFNESS_FAILED: "SET_FORCE_STIFFNESS_FAILED",
    SET_CARTESIAN_CONTROL_FAILED: "SET_CARTESIAN_CONTROL_FAILED",
}


class RequestError(StackError):
    """A refused request: `code` is a CartesianForceCtrlErrorCodes value, `axis` the axis name or ''."""

    def __init__(self, code: int, message: str, axis: str = "") -> None:
        super().__init__(message)
        self.code = code
        self.axis = axis
        self.message = message


@dataclass(frozen=True)
class RequestLimits:
    """The node's ranges a request must respect (velocity range, force range); None: unchecked.

    `default_velocity` / `default_angular_velocity` is the V_desired of a compliant move requested without one
    (in the direction of its force limit's sign); None: such a request is refused.
    """

    max_velocity: float | None = None  # [m/s] bound on |V_desired| of linear axes
    max_angular_velocity: float | None = None  # [rad/s]
    max_force: float | None = None  # [N] bound on force limits (the global limit trips first anyway)
    max_torque: float | None = None  # [Nm]
    default_velocity: float | None = None  # [m/s]
    default_angular_velocity: float | None = None  # [rad/s]
    min_velocity: float | None = None  # [m/s] a compliant move's |V_desired| must be above it (zeroed)
    min_angular_velocity: float | None = None  # [rad/s]

    @classmethod
    def from_settings(cls, settings: ContactControlSettings) -> RequestLimits:
        """Limits from a `ContactControlSettings`."""
        return cls(
            settings.max_velocity,
            settings.angular_velocity_limit,
            settings.global_max_force,
            settings.global_max_torque,
            settings.compliant_default_velocity_linear,
            settings.compliant_default_velocity_angular,
            settings.min_velocity_linear,
            settings.min_velocity_angular,
        )


def axis_groups(
    params: _ImpedanceParams, axis: int
) -> tuple[_Vector3, _Vector3, _Vector3, _Vector3, _Vector3]:
    """The five Vector3 of `cart_impedance_params` an axis reads (b, k, V_desired, limit, max travel).

    Args:
        params: a request's `cart_impedance_params`.
        axis: 0..5 for x, y, z, rx, ry, rz; read or write component `AXES[axis][-1]` of each.
    """
    if axis < 3:
        return (
            params.damping.translational,
            params.stiffness.translational,
            params.max_cart_vel.set.linear,
            params.max_ctrl_force.set.force,
            params.max_path_deviation.translation,
        )
    return (
        params.damping.rotational,
        params.stiffness.rotational,
        params.max_cart_vel.set.angular,
        params.max_ctrl_force.set.torque,
        params.max_path_deviation.rotation,
    )


def force_control_fields(axis: int) -> dict[str, str]:
    """Where axis `axis` reads each value in a ConfigureForceControl request (for messages)."""
    c = AXES[axis][-1]
    lin = axis < 3
    p = "cart_impedance_params"
    return {
        "law": f"direction_control_laws.{AXES[axis]}.type",
        "b": f"{p}.damping.{'translational' if lin else 'rotational'}.{c}",
        "k": f"{p}.stiffness.{'translational' if lin else 'rotational'}.{c}",
        "v": f"{p}.max_cart_vel.set.{'linear' if lin else 'angular'}.{c}",
        "limit": f"{p}.max_ctrl_force.set.{'force' if lin else 'torque'}.{c}",
        "travel": f"{p}.max_path_deviation.{'translation' if lin else 'rotation'}.{c}",
        "action": f"{p}.max_ctrl_force.exceeded_action",
    }


def laws_fields(axis: int) -> dict[str, str]:
    """Where axis `axis` reads each value in a compliant_control_msgs/ConfigureLaws request."""
    a = AXES[axis]
    return {
        "law": f"{a}.law",
        "b": f"{a}.damping",
        "k": f"{a}.stiffness",
        "v": f"{a}.velocity",
        "limit": f"{a}.force_limit",
        "travel": f"{a}.max_travel",
        "action": f"{a}.exceeded_action",
        "target": f"{a}.target_force",
    }


def _fields(req: ForceControlRequest, axis: int) -> tuple[int, float, float, float, float, float]:
    c = AXES[axis][-1]
    groups = axis_groups(req.cart_impedance_params, axis)
    law = getattr(req.direction_control_laws, AXES[axis]).type
    b, k, v, limit, travel = (float(getattr(g, c)) for g in groups)
    return int(law), b, k, v, limit, travel


def _axis_law(
    axis: int,
    fields: tuple[int, float, float, float, float, float],
    limits: RequestLimits,
    names: dict[str, str],
    action: int = EXCEEDED_STOP,
    target: float | None = None,
) -> AxisLaw:
    """One axis's law from its raw values, or a RequestError naming the field to set.

    `target` is the force tracking target; None: the message has no such field (ConfigureForceControl), so
    force tracking is an unknown law type there.
    """
    name = AXES[axis]
    law, b, k, v, limit, travel = fields
    angular = axis >= 3
    unit_f, unit_d, unit_v = ("Nm", "rad", "rad/s") if angular else ("N", "m", "m/s")
    values = {"law": law, "b": b, "k": k, "v": v, "limit": limit, "travel": travel, "action": action,
              "target": target}

    def fail(code: int, what: str, key: str) -> RequestError:
        # The field to set and what it holds: "RX reads cart_impedance_params.damping.rotational.x; got 0.0"
        where = f"{name.upper()} reads {names[key]}; got {values[key]}"
        return RequestError(code, f"axis {name} ({LAW_NAMES.get(law, law)}): {what}; {where}", name)

    if law == LAW_PATH and target is None:
        raise fail(SET_DOF_FAILED, "the path law (5) is offered through compliant_control_msgs/ConfigureLaws "
                   "only", "law")
    if law == LAW_FORCE_TRACKING and target is None:
        raise fail(
            SET_DOF_FAILED,
            "force tracking (4) is offered through compliant_control_msgs/ConfigureLaws only "
            "(service configure_laws, field target_force)",
            "law",
        )
    if law not in LAW_NAMES:
        known = "0 none, 1 follower, 2 spring, 3 compliant move" + (", 4 force tracking, 5 path"
                                                                     if target is not None else "")
        raise fail(SET_DOF_FAILED, f"unknown law type {law} ({known})", "law")
    if law == LAW_NONE:
        return AxisLaw()
    signed_limit = law == LAW_COMPLIANT_MOVE and v == 0.0  # its sign gives the direction
    if not ((limit >= 0.0 or signed_limit) and math.isfinite(limit)):
        raise fail(SET_CONTROL_FORCE_FAILED, f"force/torque limit must be finite, >= 0 {unit_f}", "limit")
    cap = limits.max_torque if angular else limits.max_force
    if cap is not None and abs(limit) > cap:
        raise fail(SET_CONTROL_FORCE_FAILED, f"force/torque limit exceeds the global {cap} {unit_f}", "limit")
    limit = abs(limit)
    if not (travel >= 0.0 and math.isfinite(travel)):
        raise fail(SET_CARTESIAN_CONTROL_FAILED, f"max path deviation must be finite, >= 0 {unit_d}",
                   "travel")
    if action not in EXCEEDED_ACTION_NAMES:
        raise fail(
            SET_CONTROL_FORCE_FAILED,
            "unknown exceeded action (0 stop, 1 move_away, 2 gravity_compensation)",
            "action",
        )
    if limit == 0.0:
        action = EXCEEDED_STOP  # nothing to exceed
    if law in (LAW_FOLLOWER, LAW_SPRING, LAW_FORCE_TRACKING) and not (b > 0.0 and math.isfinite(b)):
        raise fail(SET_CARTESIAN_CONTROL_FAILED, "damping b must be finite and > 0", "b")
    if law == LAW_SPRING:
        if not (k > 0.0 and math.isfinite(k)):
            raise fail(SET_FORCE_STIFFNESS_FAILED, "stiffness k must be finite and > 0 (1/s)", "k")
        return AxisLaw(
            LAW_SPRING, damping=b, stiffness=k, force_limit=limit, max_travel=travel, exceeded_action=action
        )
    if law == LAW_FOLLOWER:
        cap = 0.0
        if target is not None:  # ConfigureLaws: velocity caps the follower's speed (ConfigureForceControl's
            # max_cart_vel was never read for a follower and still is not)
            if not (v >= 0.0 and math.isfinite(v)):
                raise fail(SET_CARTESIAN_CONTROL_FAILED, f"speed cap must be finite, >= 0 {unit_v} (0: none)",
                           "v")
            cap = v
        return AxisLaw(LAW_FOLLOWER, damping=b, velocity=cap, force_limit=limit, max_travel=travel,
                       exceeded_action=action)
    if law == LAW_PATH:
        if not (k > 0.0 and math.isfinite(k)):
            raise fail(SET_FORCE_STIFFNESS_FAILED, "path gain k must be finite and > 0 (1/s)", "k")
        if not (b >= 0.0 and math.isfinite(b)):
            raise fail(SET_CARTESIAN_CONTROL_FAILED, "damping b must be finite, >= 0 (0: no force term)", "b")
        if action == EXCEEDED_GRAVITY_COMPENSATION and b == 0.0:
            raise fail(SET_CARTESIAN_CONTROL_FAILED, "gravity_compensation makes the axis a follower "
                       "(V = F / b) after its force limit: damping b must be > 0", "b")
        return AxisLaw(LAW_PATH, damping=b, stiffness=k, force_limit=limit, max_travel=travel,
                       exceeded_action=action)
    if law == LAW_FORCE_TRACKING:
        assert target is not None  # refused above
        return _tracking_law(axis, b, v, limit, travel, action, float(target), limits, fail)
    # compliant move
    if not (b >= 0.0 and math.isfinite(b)):
        raise fail(SET_CARTESIAN_CONTROL_FAILED, "damping b must be finite, >= 0 (0: no force term)", "b")
    if action == EXCEEDED_GRAVITY_COMPENSATION and b == 0.0:
        raise fail(
            SET_CARTESIAN_CONTROL_FAILED,
            "gravity_compensation makes the axis a follower (V = F / b) after its force limit: "
            "damping b must be > 0",
            "b",
        )
    if not math.isfinite(v):
        raise fail(SET_CARTESIAN_CONTROL_FAILED, f"desired velocity must be finite {unit_v}", "v")
    if v == 0.0:
        default = limits.default_angular_velocity if angular else limits.default_velocity
        if limit == 0.0 or default is None:
            raise fail(
                SET_CARTESIAN_CONTROL_FAILED,
                f"desired velocity must be non-zero {unit_v} (signed: the direction of the move)"
                + (f", or give a signed force/torque limit in {names['limit']} to approach at the node's "
                   f"compliant_default_velocity_{'angular' if angular else 'linear'} in its direction"
                   if default is not None else ""),
                "v",
            )
        v = math.copysign(default, fields[4])  # toward the force limit's sign
    vmax = limits.max_angular_velocity if angular else limits.max_velocity
    if vmax is not None and abs(v) > vmax:
        raise fail(SET_CARTESIAN_CONTROL_FAILED, f"desired velocity exceeds max velocity {vmax} {unit_v}",
                   "v")
    vmin = limits.min_angular_velocity if angular else limits.min_velocity
    if vmin is not None and abs(v) <= vmin:
        kind = "angular" if angular else "linear"
        raise fail(SET_CARTESIAN_CONTROL_FAILED, f"desired velocity {abs(v):g} is not above "
                   f"min_velocity_{kind} {vmin:g} {unit_v}: commands that slow are zeroed, the move would "
                   "not start", "v")
    if travel == 0.0 and limit == 0.0:
        # It would run until something else stopped it: require at least one of its two end conditions.
        raise fail(
            SET_CARTESIAN_CONTROL_FAILED,
            f"needs a max path deviation > 0 or a force/torque limit > 0 (or set {names['travel']})",
            "limit",
        )
    return AxisLaw(
        LAW_COMPLIANT_MOVE,
        damping=b,
        velocity=v,
        force_limit=limit,
        max_travel=travel,
        exceeded_action=action,
    )


def _tracking_law(
    axis: int,
    b: float,
    v: float,
    limit: float,
    travel: float,
    action: int,
    target: float,
    limits: RequestLimits,
    fail: Callable[[int, str, str], RequestError],
) -> AxisLaw:
    """The force tracking law of one axis (V = (F - target) / b), checked; `fail` builds the refusal."""
    angular = axis >= 3
    unit_f, unit_v = ("Nm", "rad/s") if angular else ("N", "m/s")
    cap = limits.max_torque if angular else limits.max_force
    if not math.isfinite(target):
        raise fail(SET_CONTROL_FORCE_FAILED, f"target force must be finite {unit_f}", "target")
    if cap is not None and abs(target) >= cap:
        raise fail(SET_CONTROL_FORCE_FAILED, f"target force must be below the global limit {cap} {unit_f}",
                   "target")
    if limit > 0.0 and limit <= abs(target):
        # The move would end the moment it arrived: a limit must leave room above the target.
        raise fail(
            SET_CONTROL_FORCE_FAILED,
            f"force/torque limit must exceed |target_force| {abs(target):g} {unit_f} (0: no limit)",
            "limit",
        )
    if not (v >= 0.0 and math.isfinite(v)):
        raise fail(
            SET_CARTESIAN_CONTROL_FAILED,
            f"approach speed must be finite, >= 0 {unit_v} (the direction is the target force's: toward the "
            "contact; 0: the node's default)",
            "v",
        )
    if v == 0.0:
        default = limits.default_angular_velocity if angular else limits.default_velocity
        v = default if default is not None else 0.0
    vmax = limits.max_angular_velocity if angular else limits.max_velocity
    if vmax is not None and v > vmax:
        raise fail(SET_CARTESIAN_CONTROL_FAILED, f"approach speed exceeds max velocity {vmax} {unit_v}", "v")
    return AxisLaw(
        LAW_FORCE_TRACKING,
        damping=b,
        velocity=v,
        force_limit=limit,
        max_travel=travel,
        exceeded_action=action,
        target=target,
    )


def _global_action(action: SimpleNamespace) -> int:
    """The one exceeded action the original message's three flags select (all false: stop)."""
    chosen = [name for name in ("stop", "gravity_compensation", "move_away") if getattr(action, name)]
    if len(chosen) > 1:
        raise RequestError(
            SET_CONTROL_FORCE_FAILED,
            "set at most one of cart_impedance_params.max_ctrl_force.exceeded_action."
            f"{{stop, gravity_compensation, move_away}}; got {', '.join(chosen)}",
        )
    codes = {name: code for code, name in EXCEEDED_ACTION_NAMES.items()}
    return codes[chosen[0]] if chosen else EXCEEDED_STOP


def validate_request(req: ForceControlRequest, limits: RequestLimits | None = None) -> list[AxisLaw]:
    """Maps a ConfigureForceControl request to six `AxisLaw`s (x, y, z, rx, ry, rz), or refuses it.

    The message's one `exceeded_action` applies to every axis with a force/torque limit > 0; axes without a
    limit cannot exceed one. A compliant move without desired velocity approaches at
    `limits.default_velocity` in the direction of its force limit's sign.

    Args:
        req: a ConfigureForceControlRequest, or anything with the same attribute tree (SimpleNamespace).
        limits: the node's velocity and force ranges; None checks only the request's own consistency.

    Raises:
        RequestError: with a CartesianForceCtrlErrorCodes code and a message naming the axis and field.
    """
    limits = limits or RequestLimits()
    try:
        action = req.cart_impedance_params.max_ctrl_force.exceeded_action
        names = ("stop", "gravity_compensation", "move_away")
        flags = SimpleNamespace(**{n: bool(getattr(action, n)) for n in names})
        raw = [_fields(req, axis) for axis in range(6)]
    except (AttributeError, TypeError, ValueError) as err:
        raise RequestError(FAILURE, f"malformed ConfigureForceControl request: {err}") from err
    code = _global_action(flags)
    return [_axis_law(axis, raw[axis], limits, force_control_fields(axis), code) for axis in range(6)]


def validate_laws_request(req: LawsRequest, limits: RequestLimits | None = None) -> list[AxisLaw]:
    """Maps a compliant_control_msgs/ConfigureLaws request (fields x .. rz, AxisLaw messages) to six laws.

    As `validate_request`, with a per-axis exceeded action; an exceeded action other than stop on an axis
    without a force limit is refused (it could never act).

    Raises:
        RequestError: a CartesianForceCtrlErrorCodes code and a message naming the field (e.g. z.damping).
    """
    limits = limits or RequestLimits()
    try:
        raw = []
        for name in AXES:
            a = getattr(req, name)
            numbers = (a.damping, a.stiffness, a.velocity, a.force_limit, a.max_travel)
            kind = int(a.law)
            damping, stiffness, velocity, force_limit, max_travel = (float(x) for x in numbers)
            values = (kind, damping, stiffness, velocity, force_limit, max_travel)
            raw.append((values, int(a.exceeded_action), float(getattr(a, "target_force", 0.0))))
    except (AttributeError, TypeError, ValueError) as err:
        raise RequestError(FAILURE, f"malformed ConfigureLaws request: {err}") from err
    laws = []
    for axis, (values, action, target) in enumerate(raw):
        law = _axis_law(axis, values, limits, laws_fields(axis), action, target)
        if law.law and action != EXCEEDED_STOP and law.force_limit == 0.0:
            name = AXES[axis]
            raise RequestError(
                SET_CONTROL_FORCE_FAILED,
                f"axis {name} ({LAW_NAMES[law.law]}): exceeded_action {EXCEEDED_ACTION_NAMES[action]} acts "
                f"when the force/torque limit is reached: set {name}.force_limit > 0; got 0.0",
                name,
            )
        laws.append(law)
    return laws


def _vec3() -> SimpleNamespace:
    return SimpleNamespace(x=0.0, y=0.0, z=0.0)


def empty_request() -> SimpleNamespace:
    """A request-shaped tree of zeros (every axis TYPE_UNKNOWN), for tests and Qt-free form code."""
    params = SimpleNamespace(
        tool="",
        stiffness=SimpleNamespace(translational=_vec3(), rotational=_vec3()),
        damping=SimpleNamespace(translational=_vec3(), rotational=_vec3()),
        max_cart_vel=SimpleNamespace(set=SimpleNamespace(linear=_vec3(), angular=_vec3())),
        max_ctrl_force=SimpleNamespace(
            set=SimpleNamespace(force=_vec3(), torque=_vec3()),
            exceeded_action=SimpleNamespace(stop=False, gravity_compensation=False, move_away=False),
        ),
        max_path_deviation=SimpleNamespace(translation=_vec3(), rotation=_vec3()),
        null_space_params=SimpleNamespace(link_names=[], stiffness=[], damping=[]),
    )
    laws = SimpleNamespace(**{name: SimpleNamespace(type=LAW_NONE) for name in AXES})
    force_ctrl = SimpleNamespace(DOF="", force=0.0, stiffness=0.0)
    return SimpleNamespace(
        cart_impedance_params=params, cart_force_control=force_ctrl, direction_control_laws=laws
    )


def fill_request(req: _ForceRequestT, laws: Sequence[AxisLaw]) -> _ForceRequestT:
    """Writes six laws into a request (genpy message or `empty_request()`) and returns it; drops d_offset.

    The exceeded_action flags get the laws' common action (stop when no axis has a force limit).

    Raises:
        ValueError: not six laws, or axes with force limits disagree on the exceeded action.
    """
    if len(laws) != 6:
        raise ValueError(f"need 6 laws (x, y, z, rx, ry, rz), got {len(laws)}")
    if any(law.law == LAW_FORCE_TRACKING for law in laws):
        raise ValueError("ConfigureForceControl has no force tracking law; use ConfigureLaws")
    p = req.cart_impedance_params
    for axis, law in enumerate(laws):
        c = AXES[axis][-1]
        groups = axis_groups(p, axis)
        values = (law.damping, law.stiffness, law.velocity, law.force_limit, law.max_travel)
        for group, value in zip(groups, values, strict=True):
            setattr(group, c, float(value))
        getattr(req.direction_control_laws, AXES[axis]).type = law.law
    action = _common_action(laws)
    flags = p.max_ctrl_force.exceeded_action
    for code, name in EXCEEDED_ACTION_NAMES.items():
        setattr(flags, name, code == action)
    return req


def _common_action(laws: Sequence[AxisLaw]) -> int:
    """The one exceeded action of the laws with a force limit (the original message has only one)."""
    actions = {law.exceeded_action for law in laws if law.law and law.force_limit > 0.0}
    if len(actions) > 1:
        raise ValueError("ConfigureForceControl has one exceeded_action for all axes; use ConfigureLaws")
    return actions.pop() if actions else EXCEEDED_STOP


def empty_laws_request() -> SimpleNamespace:
    """A ConfigureLaws-shaped request of zeros (every axis NONE), for tests and Qt-free code."""
    fields = (
        "law", "damping", "stiffness", "velocity", "force_limit", "max_travel", "exceeded_action",
        "target_force",
    )
    return SimpleNamespace(**{name: SimpleNamespace(**dict.fromkeys(fields, 0)) for name in AXES})


def fill_laws_request(req: _LawsRequestT, laws: Sequence[AxisLaw]) -> _LawsRequestT:
    """Writes six laws into a ConfigureLaws request (genpy message or `empty_laws_request()`)."""
    if len(laws) != 6:
        raise ValueError(f"need 6 laws (x, y, z, rx, ry, rz), got {len(laws)}")
    for name, law in zip(AXES, laws, strict=True):
        a = getattr(req, name)
        a.law, a.exceeded_action = law.law, law.exceeded_action
        a.damping, a.stiffness, a.velocity = float(law.damping), float(law.stiffness), float(law.velocity)
        a.force_limit, a.max_travel = float(law.force_limit), float(law.max_travel)
        a.target_force = float(law.target)
    return req
