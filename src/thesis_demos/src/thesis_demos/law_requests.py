"""The stack's law requests for a scenario: ConfigureForceControl (the original service) and ConfigureLaws
(force tracking), built from the scenario's per-axis laws (pure: message classes only, no rospy)."""

from __future__ import annotations

from cartesian_impedance_msgs.srv import ConfigureForceControlRequest
from compliant_control_msgs.srv import ConfigureLawsRequest

from thesis_demos.scenarios import AXES, AxisLaw, Scenario

__all__ = ["build_laws_request", "build_request"]

_ACTIONS = {"stop": 0, "move_away": 1, "gravity_compensation": 2}  # compliant_control_msgs/AxisLaw ACTION_*


def build_request(scenario: Scenario) -> ConfigureForceControlRequest:
    """The ConfigureForceControl request for a scenario (the mapping in contact_control's README)."""
    req = ConfigureForceControlRequest()
    p = req.cart_impedance_params
    for axis in AXES:
        law = scenario.laws.get(axis)
        if law is None:
            continue
        getattr(req.direction_control_laws, axis).type = law.law
        rotational = axis.startswith("r")
        c = axis[-1]
        setattr(p.damping.rotational if rotational else p.damping.translational, c, law.damping)
        setattr(p.stiffness.rotational if rotational else p.stiffness.translational, c, law.stiffness)
        setattr(p.max_cart_vel.set.angular if rotational else p.max_cart_vel.set.linear, c, law.velocity)
        limit = p.max_ctrl_force.set
        if rotational:
            setattr(limit.torque, c, law.torque_limit)
        else:
            setattr(limit.force, c, law.force_limit)
        setattr(
            p.max_path_deviation.rotation if rotational else p.max_path_deviation.translation,
            c,
            law.max_travel,
        )
    action = p.max_ctrl_force.exceeded_action
    if scenario.exceeded_action not in ("stop", "move_away", "gravity_compensation"):
        raise ValueError(f"{scenario.name}: unknown exceeded_action {scenario.exceeded_action!r}")
    setattr(action, scenario.exceeded_action, True)
    return req


def build_laws_request(laws: dict[str, AxisLaw], exceeded_action: str = "stop") -> ConfigureLawsRequest:
    """The compliant_control_msgs/ConfigureLaws request for laws per axis (force tracking needs it).

    `exceeded_action` applies to every axis with a force (torque) limit, as in the original message.
    """
    if exceeded_action not in _ACTIONS:
        raise ValueError(f"unknown exceeded_action {exceeded_action!r}")
    req = ConfigureLawsRequest()
    for axis, law in laws.items():
        a = getattr(req, axis)
        rotational = axis.startswith("r")
        a.law, a.damping, a.stiffness, a.velocity = law.law, law.damping, law.stiffness, law.velocity
        a.force_limit = law.torque_limit if rotational else law.force_limit
        a.max_travel, a.target_force = law.max_travel, law.target_force
        a.exceeded_action = _ACTIONS[exceeded_action] if a.force_limit > 0.0 else 0
    return req
