# ruff: noqa: E501  (the template is the file's text: its comment lines keep their length)
"""config/description.args: control_stack's make_description arguments (stock URDF, sensor frame, tool)."""

from __future__ import annotations

from robot_setup.plan import Plan
from robot_setup.templates.text import generated_by, num

__all__ = ["description_args"]


def _mounting(plan: Plan) -> str:
    """The sensor frame's comment, and --ft-rpy when it is not the flange's axes."""
    if not any(plan.tool_rpy):
        return f"# Wrist F/T sensor frame on the flange ({plan.spec.tip}), same axes as the flange.\n"
    rpy = " ".join(num(v) for v in plan.tool_rpy)
    why = plan.adapter or "TOOL_RPY"
    return (f"# Wrist F/T sensor frame on the flange ({plan.spec.tip}), turned by roll pitch yaw {rpy} rad ({why}).\n"
            f"--ft-rpy {rpy}\n")


def description_args(plan: Plan) -> str:
    name = plan.spec.name
    generated = generated_by(plan.spec, with_driver=False)
    removed = "".join(
        f"# Removed: the subtree below the flange (the tool replaces it).\n--remove-link {link}\n"
        for link in plan.removed
    )
    com = (0.0, 0.0, 0.05)
    return f"""# Arguments of control_stack's make_description for the {name} (read with: make_description @description.args);
# {generated}.
--source {plan.source}
{removed}{_mounting(plan)}--tool-parent {plan.spec.tip}
--ft-name ft_sensor
# Tool: a {num(plan.spec.tool_mass)} kg cylinder, 0.03 m radius, 0.12 m long, centre of mass 0.05 m out from the sensor [kg, m].
--tool-name tool
--tool-mass {num(plan.spec.tool_mass)}
--tool-com {num(com[0])} {num(com[1])} {num(com[2])}
--tool-shape cylinder
--tool-size 0.03 0.12
# Tool centre point at the cylinder's end.
--tip-name tool_tip
"""
