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
    LAW_NORMAL,
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


class _Axis:
    """One axis's raw request values, the checks its laws share, and how to refuse them: the field to set
    and what it holds ("RX reads cart_impedance_params.damping.rotational.x; got 0.0")."""

    def __init__(self, axis: int, fields: tuple[int, float, float, float, float, float],
                 limits: RequestLimits, names: dict[str, str], action: int, target: float | None) -> None:
        self.name, self.angular, self.limits, self.names = AXES[axis], axis >= 3, limits, names
        self.law, self.b, self.k, self.v, self.limit, self.travel = fields
        self.signed_limit = self.limit  # a compliant move without a velocity goes toward its sign
        self.action, self.target = action, target
        self.unit_f, self.unit_d, self.unit_v = ("Nm", "rad", "rad/s") if self.angular else ("N", "m", "m/s")

    def fail(self, code: int, what: str, key: str) -> RequestError:
        values = {"law": self.law, "b": self.b, "k": self.k, "v": self.v, "limit": self.signed_limit,
                  "travel": self.travel, "action": self.action, "target": self.target}
        where = f"{self.name.upper()} reads {self.names[key]}; got {values[key]}"
        return RequestError(code, f"axis {self.name} ({LAW_NAMES.get(self.law, self.law)}): {what}; {where}",
                            self.name)

    def require(self, ok: bool, code: int, what: str, key: str) -> None:
        if not ok:
            raise self.fail(code, what, key)

    def pick(self, linear: float | None, angular: float | None) -> float | None:
        return angular if self.angular else linear

    def check_ends(self) -> None:
        """The force/torque limit (finite, >= 0 but for a compliant move's signed one, within the global
        limit), the max path deviation and the exceeded action; no limit: nothing to exceed."""
        limit, unit_f = self.limit, self.unit_f
        signed = self.law == LAW_COMPLIANT_MOVE and self.v == 0.0
        self.require((limit >= 0.0 or signed) and math.isfinite(limit), SET_CONTROL_FORCE_FAILED,
                     f"force/torque limit must be finite, >= 0 {unit_f}", "limit")
        cap = self.pick(self.limits.max_force, self.limits.max_torque)
        self.require(cap is None or abs(limit) <= cap, SET_CONTROL_FORCE_FAILED,
                     f"force/torque limit exceeds the global {cap} {unit_f}", "limit")
        self.limit = abs(limit)
        self.require(self.travel >= 0.0 and math.isfinite(self.travel), SET_CARTESIAN_CONTROL_FAILED,
                     f"max path deviation must be finite, >= 0 {self.unit_d}", "travel")
        self.require(self.action in EXCEEDED_ACTION_NAMES, SET_CONTROL_FORCE_FAILED,
                     "unknown exceeded action (0 stop, 1 move_away, 2 gravity_compensation)", "action")
        if self.limit == 0.0:
            self.action = EXCEEDED_STOP

    def damping(self, required: bool) -> float:
        """b > 0 (`required`), else b >= 0 with no force term at 0, unless gravity compensation follows."""
        b, finite = self.b, math.isfinite(self.b)
        if required:
            self.require(b > 0.0 and finite, SET_CARTESIAN_CONTROL_FAILED, "damping b must be finite and > 0",
                         "b")
            return b
        self.require(b >= 0.0 and finite, SET_CARTESIAN_CONTROL_FAILED,
                     "damping b must be finite, >= 0 (0: no force term)", "b")
        self.require(not (self.action == EXCEEDED_GRAVITY_COMPENSATION and b == 0.0),
                     SET_CARTESIAN_CONTROL_FAILED,
                     "gravity_compensation makes the axis a follower (V = F / b) after its force limit: "
                     "damping b must be > 0", "b")
        return b

    def gain(self, what: str) -> float:
        self.require(self.k > 0.0 and math.isfinite(self.k), SET_FORCE_STIFFNESS_FAILED,
                     f"{what} must be finite and > 0 (1/s)", "k")
        return self.k

    def law_with(self, law: int, **values: float) -> AxisLaw:
        return AxisLaw(law, force_limit=self.limit, max_travel=self.travel, exceeded_action=self.action,
                       **values)


def _follower(a: _Axis) -> AxisLaw:
    b, cap = a.damping(required=True), 0.0
    if a.target is not None:  # ConfigureLaws: velocity caps the follower's speed (ConfigureForceControl's
        # max_cart_vel was never read for a follower and still is not)
        a.require(a.v >= 0.0 and math.isfinite(a.v), SET_CARTESIAN_CONTROL_FAILED,
                  f"speed cap must be finite, >= 0 {a.unit_v} (0: none)", "v")
        cap = a.v
    return a.law_with(LAW_FOLLOWER, damping=b, velocity=cap)


def _spring(a: _Axis) -> AxisLaw:
    b = a.damping(required=True)
    return a.law_with(LAW_SPRING, damping=b, stiffness=a.gain("stiffness k"))


def _path(a: _Axis) -> AxisLaw:
    k = a.gain("path gain k")
    return a.law_with(LAW_PATH, damping=a.damping(required=False), stiffness=k)


def _force_tracking(a: _Axis) -> AxisLaw:
    """V = (F - target) / b: a target within the global limit and below the axis's own, an approach speed."""
    b = a.damping(required=True)
    assert a.target is not None  # refused before: only ConfigureLaws has the field
    target, unit_f, unit_v = float(a.target), a.unit_f, a.unit_v
    cap = a.pick(a.limits.max_force, a.limits.max_torque)
    a.require(math.isfinite(target), SET_CONTROL_FORCE_FAILED, f"target force must be finite {unit_f}",
              "target")
    a.require(cap is None or abs(target) < cap, SET_CONTROL_FORCE_FAILED,
              f"target force must be below the global limit {cap} {unit_f}", "target")
    # A limit at or under the target would end the move the moment it arrived.
    a.require(not (0.0 < a.limit <= abs(target)), SET_CONTROL_FORCE_FAILED,
              f"force/torque limit must exceed |target_force| {abs(target):g} {unit_f} (0: no limit)",
              "limit")
    a.require(a.v >= 0.0 and math.isfinite(a.v), SET_CARTESIAN_CONTROL_FAILED,
              f"approach speed must be finite, >= 0 {unit_v} (the direction is the target force's: toward "
              "the contact; 0: the node's default)", "v")
    v = a.v
    if v == 0.0:
        v = a.pick(a.limits.default_velocity, a.limits.default_angular_velocity) or 0.0
    vmax = a.pick(a.limits.max_velocity, a.limits.max_angular_velocity)
    a.require(vmax is None or v <= vmax, SET_CARTESIAN_CONTROL_FAILED,
              f"approach speed exceeds max velocity {vmax} {unit_v}", "v")
    return a.law_with(LAW_FORCE_TRACKING, damping=b, velocity=v, target=target)


def _compliant_move(a: _Axis) -> AxisLaw:
    """V = V_desired + F / b toward a max travel or a force limit (at least one of them)."""
    b, unit_v = a.damping(required=False), a.unit_v
    a.require(math.isfinite(a.v), SET_CARTESIAN_CONTROL_FAILED, f"desired velocity must be finite {unit_v}",
              "v")
    v = a.v
    if v == 0.0:
        default = a.pick(a.limits.default_velocity, a.limits.default_angular_velocity)
        kind = "angular" if a.angular else "linear"
        a.require(a.limit != 0.0 and default is not None, SET_CARTESIAN_CONTROL_FAILED,
                  f"desired velocity must be non-zero {unit_v} (signed: the direction of the move)"
                  + (f", or give a signed force/torque limit in {a.names['limit']} to approach at the node's "
                     f"compliant_default_velocity_{kind} in its direction" if default is not None else ""),
                  "v")
        assert default is not None
        v = math.copysign(default, a.signed_limit)  # toward the force limit's sign
    vmax = a.pick(a.limits.max_velocity, a.limits.max_angular_velocity)
    a.require(vmax is None or abs(v) <= vmax, SET_CARTESIAN_CONTROL_FAILED,
              f"desired velocity exceeds max velocity {vmax} {unit_v}", "v")
    vmin = a.pick(a.limits.min_velocity, a.limits.min_angular_velocity)
    if vmin is not None and abs(v) <= vmin:
        kind = "angular" if a.angular else "linear"
        raise a.fail(SET_CARTESIAN_CONTROL_FAILED, f"desired velocity {abs(v):g} is not above "
                     f"min_velocity_{kind} {vmin:g} {unit_v}: commands that slow are zeroed, the move would "
                     "not start", "v")
    # It would run until something else stopped it: at least one of its two end conditions.
    a.require(a.travel != 0.0 or a.limit != 0.0, SET_CARTESIAN_CONTROL_FAILED,
              f"needs a max path deviation > 0 or a force/torque limit > 0 (or set {a.names['travel']})",
              "limit")
    return a.law_with(LAW_COMPLIANT_MOVE, damping=b, velocity=v)


def _normal(a: _Axis) -> AxisLaw:
    """W = k theta on RX/RY: the tool's axis turned onto the contact normal (normal.NormalFollower)."""
    a.require(a.name in ("rx", "ry"), SET_DOF_FAILED,
              "the normal law turns the tool's axis about RX and RY only", "law")
    k = a.gain("normal gain k")
    a.require(a.v >= 0.0 and math.isfinite(a.v), SET_CARTESIAN_CONTROL_FAILED,
              f"turning speed cap must be finite, >= 0 {a.unit_v} (0: only the node's clamp)", "v")
    vmax = a.limits.max_angular_velocity
    a.require(vmax is None or a.v <= vmax, SET_CARTESIAN_CONTROL_FAILED,
              f"turning speed cap exceeds max velocity {vmax} {a.unit_v}", "v")
    return a.law_with(LAW_NORMAL, stiffness=k, velocity=a.v)


#: What each law checks and builds (LAW_NONE needs nothing).
_LAWS: dict[int, Callable[[_Axis], AxisLaw]] = {
    LAW_FOLLOWER: _follower,
    LAW_SPRING: _spring,
    LAW_COMPLIANT_MOVE: _compliant_move,
    LAW_FORCE_TRACKING: _force_tracking,
    LAW_PATH: _path,
    LAW_NORMAL: _normal,
}
_LAWS_REQUEST_ONLY: dict[int, str] = {
    LAW_PATH: "the path law (5) is offered through compliant_control_msgs/ConfigureLaws only",
    LAW_FORCE_TRACKING: "force tracking (4) is offered through compliant_control_msgs/ConfigureLaws only "
                        "(service configure_laws, field target_force)",
    LAW_NORMAL: "the normal law (6) is offered through compliant_control_msgs/ConfigureLaws only",
}


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
    force tracking and the path law are not offered there.
    """
    a = _Axis(axis, fields, limits, names, action, target)
    if target is None and a.law in _LAWS_REQUEST_ONLY:
        raise a.fail(SET_DOF_FAILED, _LAWS_REQUEST_ONLY[a.law], "law")
    if a.law not in LAW_NAMES:
        known = "0 none, 1 follower, 2 spring, 3 compliant move" + (", 4 force tracking, 5 path, 6 normal"
                                                                     if target is not None else "")
        raise a.fail(SET_DOF_FAILED, f"unknown law type {a.law} ({known})", "law")
    if a.law == LAW_NONE:
        return AxisLaw()
    a.check_ends()
    return _LAWS[a.law](a)


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
