# ruff: noqa: E501  (the template is the file's text: its comment lines keep their length)
"""config/sim.yaml: the MuJoCo scene (table, obstacle, start pose, servo gains) mujoco_driver reads."""

from __future__ import annotations

import math

from jog_arm.settings import JogSettings

from robot_setup.plan import Plan
from robot_setup.templates.text import generated_by, joints, num

__all__ = ["held_section", "sim_yaml"]


def held_section(plan: Plan, indent: int = 0) -> str:
    """`held_joints:` with its comment (also in jog_arm's files); empty when every joint is an arm joint."""
    if not plan.held:
        return ""
    values = joints([v for _, v in plan.held], [f"- {j}" for j, _ in plan.held], "{:g}", indent + 2)
    pad = " " * indent
    return f"""
{pad}# Joints outside the arm ({plan.base} .. {plan.spec.tip}): held here [rad or m] (make robot HELD=, default 0
{pad}# within the limits); jog_arm and named_poses never move them. sim.yaml and jog_arm*.yaml list the same.
{pad}held_joints:
{values}
"""


def servo_note(plan: Plan) -> str:
    """Why the gains are lower than the rule's, as the comment's tail ("" when they are not)."""
    return f";\n# then {plan.servo_note}" if plan.servo_note else ""


def linear_note(plan: Plan) -> str:
    """How a prismatic joint's gains follow from the rule, as the comment's tail ("" without one)."""
    if not plan.linear:
        return ""
    return f";\n# {', '.join(plan.linear)} (prismatic): the same numbers in N/m per N of effort"


def sim_yaml(plan: Plan) -> str:
    name = plan.spec.name
    s = plan.start
    generated = generated_by(plan.spec, with_driver=False)
    closest = min((m for m in s.margins if math.isfinite(m)), default=math.inf)
    return f"""# MuJoCo scene for the {name} (read by mujoco_driver); {generated}.
# Units: m, rad, kg, s, N, Nm. Everything is in the robot's base frame (the URDF root), which is MuJoCo's world
# frame; the table top is its z = 0 plane. The tool (mass, shape) is in description.args.

timestep: 0.002            # [s] physics step; the driver steps in real time at 1/timestep
integrator: implicitfast   # implicit servo damping: stable with stiff gains

links:                     # URDF links created by make_description
  ft_sensor: ft_sensor     # F/T sensor frame: the wrench is reported here
  tool: tool               # the body pushes are applied to (at its centre of mass)
  eef: tool_tip            # end-effector frame (tool centre point)

table:
  size: [1.2, 0.8]         # top extents x, y [m]
  thickness: 0.05          # [m]
  height: 0.75             # top above the floor [m]
  center: [0.3, 0.0]       # top centre in the base frame [m]

# Start pose (found by make robot): tool pointing down, tool tip at ({s.tip[0]:.3f}, {s.tip[1]:.3f}, {s.tip[2]:.3f}) m;
# condition number {s.condition:.2f} (jog_arm's, length scale 0.4 m), at most {s.worst_condition:.2f} on the demos'
# motions; every bounded joint >= {closest:.2f} rad from its limits (>= {s.min_margin:.2f} rad on the motions).
start_pose:
{joints(s.q, plan.joints)}
{held_section(plan)}
# Obstacle for the compliant-move demo: a block on the table under the tool tip, its top
# (z = {plan.obstacle_size[2]:.3f}) {plan.gap * 100:.1f} cm below the tip at the start pose.
obstacle:
  position: [{plan.obstacle_position[0]:.3f}, {plan.obstacle_position[1]:.3f}, {plan.obstacle_position[2]:.4f}]   # box centre [m]
  size: [{plan.obstacle_size[0]:.2f}, {plan.obstacle_size[1]:.2f}, {plan.obstacle_size[2]:.3f}]          # full extents [m]
  rpy: [0.0, 0.0, 0.0]              # [rad]

# Joint servos: torque = kp (q_set - q) + kv (qd_set - qd) + payload feed-forward, limited to the URDF
# efforts ({', '.join(num(e) for e in plan.efforts)} Nm{"; N for a prismatic joint" if plan.linear else ""}). kp = 120 Nm/rad per Nm of effort (1000..20000), kv = 0.02 s x kp{servo_note(plan)}{linear_note(plan)}.
servo:
  kp:                      # [Nm/rad{"; N/m for a prismatic joint" if plan.linear else ""}]
{joints(plan.kp, plan.servo_joints, "{:.1f}", 4)}
  kv:                      # [Nm s/rad{"; N s/m" if plan.linear else ""}]
{joints(plan.kv, plan.servo_joints, "{:.1f}", 4)}
  armature: {plan.armature}            # reflected rotor inertia per joint [kg m^2]
  max_acceleration: {plan.acceleration + 1.0:.1f}    # [rad/s^2] setpoint acceleration limit (above jog_arm's {plan.acceleration:g} rad/s^2)
  max_deceleration: {plan.acceleration * JogSettings.contact_stop_scale + 1.0:.1f}   # [rad/s^2] while slowing down (above jog_arm's contact stop, {JogSettings.contact_stop_scale:g} x {plan.acceleration:g}; a guess at what the arm can)
  payload_feedforward: true

wrench_noise:              # Gaussian sensor noise (0: exact)
  force_std: 0.0           # [N]
  torque_std: 0.0          # [Nm]
  seed: 0
"""
