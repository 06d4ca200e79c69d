"""ConfigureForceControl request <-> six per-axis laws, with validation (no ROS import; duck-typed).

Mapping per axis (SPEC section 3), with p = req.cart_impedance_params and c the axis letter x, y or z:

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
from collections.abc import Sequence
from dataclasses import dataclass
from types import SimpleNamespace
from typing import Any

from contact_control.axes import AXES, LAW_COMPLIANT_MOVE, LAW_FOLLOWER, LAW_NAMES, LAW_NONE, LAW_SPRING
from contact_control.laws import AxisLaw

__all__ = [
    "FAILURE",
    "SET_CARTESIAN_CONTROL_FAILED",
    "SET_CONTROL_FORCE_FAILED",
    "SET_DOF_FAILED",
    "SET_FORCE_STIFFNESS_FAILED",
    "SUCCESS",
    "RequestError",
    "RequestLimits",
    "axis_groups",
    "empty_request",
    "fill_request",
    "validate_request",
]

# cartesian_impedance_msgs/CartesianForceCtrlErrorCodes
SUCCESS = 1
FAILURE = 99999  # malformed request object, or the controller cannot take laws now (safety latched)
SET_DOF_FAILED = -1  # unknown law type on an axis
SET_CONTROL_FORCE_FAILED = -2  # force/torque limit NaN, negative, above the global limit; unsupported action
SET_FORCE_STIFFNESS_FAILED = -3  # spring stiffness k <= 0 or NaN
SET_CARTESIAN_CONTROL_FAILED = -4  # damping, desired velocity or max travel invalid


class RequestError(ValueError):
    """A refused request: `code` is a CartesianForceCtrlErrorCodes value, `axis` the axis name or ''."""

    def __init__(self, code: int, message: str, axis: str = "") -> None:
        super().__init__(message)
        self.code = code
        self.axis = axis
        self.message = message


@dataclass(frozen=True)
class RequestLimits:
    """The node's ranges a request must respect (velocity range, force range); None: unchecked."""

    max_velocity: float | None = None  # [m/s] bound on |V_desired| of linear axes
    max_angular_velocity: float | None = None  # [rad/s]
    max_force: float | None = None  # [N] bound on force limits (the global limit trips first anyway)
    max_torque: float | None = None  # [Nm]

    @classmethod
    def from_settings(cls, settings: Any) -> RequestLimits:
        """Limits from a `ContactControlSettings`."""
        return cls(
            settings.max_velocity,
            settings.angular_velocity_limit,
            settings.global_max_force,
            settings.global_max_torque,
        )


def axis_groups(params: Any, axis: int) -> tuple[Any, Any, Any, Any, Any]:
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


def _fields(req: Any, axis: int) -> tuple[int, float, float, float, float, float]:
    c = AXES[axis][-1]
    groups = axis_groups(req.cart_impedance_params, axis)
    law = getattr(req.direction_control_laws, AXES[axis]).type
    b, k, v, limit, travel = (float(getattr(g, c)) for g in groups)
    return int(law), b, k, v, limit, travel


def _axis_law(
    axis: int, fields: tuple[int, float, float, float, float, float], limits: RequestLimits
) -> AxisLaw:
    name = AXES[axis]
    law, b, k, v, limit, travel = fields
    angular = axis >= 3
    unit_f, unit_d, unit_v = ("Nm", "rad", "rad/s") if angular else ("N", "m", "m/s")

    def fail(code: int, what: str) -> RequestError:
        return RequestError(code, f"axis {name} ({LAW_NAMES.get(law, law)}): {what}", name)

    if law not in LAW_NAMES:
        raise fail(SET_DOF_FAILED, f"unknown law type {law} (0 none, 1 follower, 2 spring, 3 compliant move)")
    if law == LAW_NONE:
        return AxisLaw()
    if not (limit >= 0.0 and math.isfinite(limit)):
        raise fail(SET_CONTROL_FORCE_FAILED, f"force/torque limit must be finite, >= 0 {unit_f}; got {limit}")
    cap = limits.max_torque if angular else limits.max_force
    if cap is not None and limit > cap:
        raise fail(SET_CONTROL_FORCE_FAILED, f"force/torque limit {limit} {unit_f} exceeds the global {cap}")
    if not (travel >= 0.0 and math.isfinite(travel)):
        raise fail(
            SET_CARTESIAN_CONTROL_FAILED, f"max path deviation must be finite, >= 0 {unit_d}; got {travel}"
        )
    if law in (LAW_FOLLOWER, LAW_SPRING) and not (b > 0.0 and math.isfinite(b)):
        raise fail(SET_CARTESIAN_CONTROL_FAILED, f"damping b must be finite and > 0, got {b}")
    if law == LAW_SPRING:
        if not (k > 0.0 and math.isfinite(k)):
            raise fail(SET_FORCE_STIFFNESS_FAILED, f"stiffness k must be finite and > 0, got {k}")
        return AxisLaw(LAW_SPRING, damping=b, stiffness=k, force_limit=limit, max_travel=travel)
    if law == LAW_FOLLOWER:
        return AxisLaw(LAW_FOLLOWER, damping=b, force_limit=limit, max_travel=travel)
    # compliant move
    if not (b >= 0.0 and math.isfinite(b)):
        raise fail(
            SET_CARTESIAN_CONTROL_FAILED, f"damping b must be finite, >= 0 (0: no force term); got {b}"
        )
    if not (v != 0.0 and math.isfinite(v)):
        raise fail(
            SET_CARTESIAN_CONTROL_FAILED, f"desired velocity must be finite, non-zero {unit_v}; got {v}"
        )
    vmax = limits.max_angular_velocity if angular else limits.max_velocity
    if vmax is not None and abs(v) > vmax:
        raise fail(SET_CARTESIAN_CONTROL_FAILED, f"desired velocity {v} {unit_v} exceeds max velocity {vmax}")
    if travel == 0.0 and limit == 0.0:
        # It would run until something else stopped it: require at least one of its two end conditions.
        raise fail(SET_CARTESIAN_CONTROL_FAILED, "needs a max path deviation > 0 or a force/torque limit > 0")
    return AxisLaw(LAW_COMPLIANT_MOVE, damping=b, velocity=v, force_limit=limit, max_travel=travel)


def validate_request(req: Any, limits: RequestLimits | None = None) -> list[AxisLaw]:
    """Maps a ConfigureForceControl request to six `AxisLaw`s (x, y, z, rx, ry, rz), or refuses it.

    Args:
        req: a ConfigureForceControlRequest, or anything with the same attribute tree (SimpleNamespace).
        limits: the node's velocity and force ranges; None checks only the request's own consistency.

    Raises:
        RequestError: with a CartesianForceCtrlErrorCodes code and a message naming the axis and field.
    """
    limits = limits or RequestLimits()
    try:
        action = req.cart_impedance_params.max_ctrl_force.exceeded_action
        unsupported = [name for name in ("gravity_compensation", "move_away") if getattr(action, name)]
        raw = [_fields(req, axis) for axis in range(6)]
    except (AttributeError, TypeError, ValueError) as err:
        raise RequestError(FAILURE, f"malformed ConfigureForceControl request: {err}") from err
    if unsupported:
        raise RequestError(
            SET_CONTROL_FORCE_FAILED,
            f"exceeded_action {', '.join(unsupported)} is not supported; only stop (the move ends). "
            "Tool gravity compensation is the node's tool_mass/tool_com parameters.",
        )
    return [_axis_law(axis, raw[axis], limits) for axis in range(6)]


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


def fill_request(req: Any, laws: Sequence[AxisLaw]) -> Any:
    """Writes six laws into a request (genpy message or `empty_request()`) and returns it; drops d_offset."""
    if len(laws) != 6:
        raise ValueError(f"need 6 laws (x, y, z, rx, ry, rz), got {len(laws)}")
    p = req.cart_impedance_params
    for axis, law in enumerate(laws):
        c = AXES[axis][-1]
        groups = axis_groups(p, axis)
        values = (law.damping, law.stiffness, law.velocity, law.force_limit, law.max_travel)
        for group, value in zip(groups, values, strict=True):
            setattr(group, c, float(value))
        getattr(req.direction_control_laws, AXES[axis]).type = law.law
    return req
