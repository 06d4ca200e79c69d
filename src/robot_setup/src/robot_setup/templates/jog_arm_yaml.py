# ruff: noqa: E501  (the template is the file's text: its comment lines keep their length)
"""config/jog_arm.yaml: jog_arm_server on the simulated arm, with the singularity thresholds make robot measured."""

from __future__ import annotations

from robot_setup.plan import Plan
from robot_setup.templates.sim_yaml import held_section
from robot_setup.templates.text import generated_by
from robot_setup.tip_response import MIN_TIP_ACCELERATION

__all__ = ["chain", "jog_arm_yaml", "thresholds"]


def chain(plan: Plan) -> str:
    """The controlled joints and the held ones, when the description has joints outside the arm (also in
    jog_arm_hardware.yaml); empty otherwise (jog_arm takes the joints from the root to the tip)."""
    if not plan.held:
        return ""
    return f"""
# The arm's joints ({plan.base} .. {plan.spec.tip}), in the order of the driver's velocity controller:
joint_names: [{", ".join(plan.joints)}]
{held_section(plan).lstrip()}"""


def thresholds(plan: Plan) -> str:
    """The singularity thresholds: also in jog_arm_hardware.yaml."""
    s = plan.start
    return f"""# Condition number of the tip Jacobian with linear rows / singularity_length_scale, measured by make robot:
# {s.condition:.2f} at the start pose, at most {s.worst_condition:.2f} on the demos' motions; the threshold is 1.2 x that.
singularity_threshold: {plan.threshold:g}
hard_stop_singularity_threshold: {plan.hard_stop:g}
singularity_length_scale: 0.4       # [m] jog_arm's default, stated because the thresholds depend on it
# Every joint's acceleration limit: the tip can accelerate at least {MIN_TIP_ACCELERATION:g} m/s^2 along X, Y and Z at the start
# pose (make robot; a smaller arm needs more, robot_setup README).
default_max_acceleration: {plan.acceleration:.1f}       # [rad/s^2]
"""


def jog_arm_yaml(plan: Plan) -> str:
    generated = generated_by(plan.spec, with_driver=False)
    return f"""# jog_arm_server settings for the simulated {plan.spec.name}, loaded on top of jog_arm's config/jog_arm.yaml;
# {generated}. Units: m, rad, s.

ee_frame_name: tool_tip             # tool centre point from make_description
planning_frame: {plan.base}
cmd_frame: {plan.base}

joint_topic: joint_states
cmd_in_topic: jog_arm_server/delta_jog_cmds
cmd_out_topic: joint_group_velocity_controller/command   # the driver's velocity input
command_in_type: speed_units
command_out_type: velocity_array
simu: false

pub_period: 0.002
publish_on_command: true
publish_synchronously: true         # the driver's command_timeout stops the arm if we stall
integrate_from: measured
incoming_cmd_timeout: 0.1           # [s]
joint_state_timeout: 0.2            # [s]
low_pass_filter_coeff: 2.0

{thresholds(plan)}{chain(plan)}"""
