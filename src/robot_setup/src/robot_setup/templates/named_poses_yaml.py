# ruff: noqa: E501  (the template is the file's text: its comment lines keep their length)
"""config/named_poses.yaml: `start` and `home` for named_poses' ~move_to."""

from __future__ import annotations

from robot_setup.plan import Plan
from robot_setup.templates.text import generated_by, joints

__all__ = ["named_poses_yaml"]


def named_poses_yaml(plan: Plan) -> str:
    generated = generated_by(plan.spec, with_driver=False)
    return f"""# Named joint configurations of the {plan.spec.name} [rad] for named_poses' ~move_to; {generated}.
# `start` is sim.yaml's start_pose; `home` is it with the tool tip lifted.
poses:
  start:
{joints(plan.start.q, plan.joints, indent=4)}
  home:
{joints(plan.home, plan.joints, indent=4)}
max_velocity: 0.5           # [rad/s] every joint (capped by the URDF's velocity limits)
max_acceleration: 1.0       # [rad/s^2] every joint
"""
