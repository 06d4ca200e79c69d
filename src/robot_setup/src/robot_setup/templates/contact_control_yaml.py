# ruff: noqa: E501  (the template is the file's text: its comment lines keep their length)
"""config/contact_control.yaml: contact_control_node on the simulated arm (frames, tool, filter tuning)."""

from __future__ import annotations

from robot_setup.plan import Plan
from robot_setup.templates.text import generated_by, num

__all__ = ["contact_control_yaml", "guide_block", "tool_block"]


def tool_block(plan: Plan) -> str:
    """The tool's compensation: also in a generic driver's contact_control_hardware.yaml."""
    return f"""# The tool below the sensor (as in config/description.args): compensated with the sensor's orientation.
tool_mass: {num(plan.spec.tool_mass)}                      # [kg]
tool_com: [0.0, 0.0, 0.05]          # [m] in the sensor frame
tare_on_startup: true
"""


def guide_block() -> str:
    """Hand-guiding (~guide) on this arm: also in every contact_control_hardware.yaml."""
    return """# Hand-guiding (~guide, the GUI's Guide button): followers with these, the tool's weight compensated.
guide_damping_linear: 50.0          # [N/(m/s)] a 10 N push: 0.2 m/s
guide_damping_angular: 4.0          # [Nm/(rad/s)] a 2 Nm twist: 0.5 rad/s
guide_max_velocity_linear: 0.25     # [m/s]
guide_max_velocity_angular: 0.5     # [rad/s]
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
{guide_block()}
# Closed-loop tuning of the simulated stack (the hand-written robot packages' values and README).
acceleration_linear: 0.4            # [m/s^2]
lp_filter_delta_t: 0.002            # [s] the simulated sensor's sample period
lp_filter_cutoff_freq: 5.0          # [Hz]
wrench_timeout: 0.25                # [s]
"""
