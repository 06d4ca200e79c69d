# ruff: noqa: E501  (the template is the file's text: its comment lines keep their length)
"""config/contact_control.yaml: contact_control_node on the simulated arm (frames, tool, filter tuning)."""

from __future__ import annotations

from robot_setup.plan import Plan
from robot_setup.templates.text import generated_by, num

__all__ = ["contact_control_yaml", "tool_block"]


def tool_block(plan: Plan) -> str:
    """The tool's compensation: also in a generic driver's contact_control_hardware.yaml."""
    return f"""# The tool below the sensor (as in config/description.args): compensated with the sensor's orientation.
tool_mass: {num(plan.spec.tool_mass)}                      # [kg]
tool_com: [0.0, 0.0, 0.05]          # [m] in the sensor frame
tare_on_startup: true
"""


def contact_control_yaml(plan: Plan) -> str:
    generated = generated_by(plan.spec, with_driver=False)
    return f"""# contact_control_node settings for the simulated {plan.spec.name}, loaded on top of contact_control's
# config/contact_control.yaml; {generated}. Units: m, kg, s, N.

ft_in_topic: wrench                                 # the MuJoCo driver's WrenchStamped (frame ft_sensor)
velocity_out_topic: jog_arm_server/contact_cmds   # into jog_arm
move_group: manipulator                             # informational

fixed_frame: {plan.base}
velocity_command_frame: {plan.base}   # = jog_arm's planning_frame
ft_sensor_frame: ft_sensor
control_frame: {plan.base}            # laws act along the base axes
eef_frame: tool_tip

{tool_block(plan)}
# Closed-loop tuning of the simulated stack (the hand-written robot packages' values and README).
acceleration_linear: 0.4            # [m/s^2]
lp_filter_delta_t: 0.002            # [s] the simulated sensor's sample period
lp_filter_cutoff_freq: 5.0          # [Hz]
wrench_timeout: 0.25                # [s]
"""
