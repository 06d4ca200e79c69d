# ruff: noqa: E501  (the template is the file's text: its comment lines keep their length)
"""config/contact_control_hardware.yaml: contact_control_node against a real driver, generic or a profile's."""

from __future__ import annotations

from robot_setup.plan import Plan, command_line
from robot_setup.templates.contact_control_yaml import guide_block, tool_block
from robot_setup.templates.driver_text import frame_origin, model_words, written
from robot_setup.templates.text import comment, num

__all__ = ["contact_control_hardware_yaml"]


def contact_control_hardware_yaml(plan: Plan) -> str:
    if not plan.driver.generic:
        return _for_profile(plan)
    return f"""# contact_control_node settings for a real {plan.spec.name} with a wrist F/T sensor publishing WrenchStamped on
# `wrench` (written by make robot for a generic driver; run unchanged against mujoco_driver's emulated_robot.launch without a profile; adapt to your drivers). Loaded on top of contact_control's defaults.

ft_in_topic: wrench
velocity_out_topic: jog_arm_server/contact_cmds
move_group: manipulator
fixed_frame: {plan.base}
velocity_command_frame: {plan.base}
ft_sensor_frame: ft_sensor
control_frame: {plan.base}
eef_frame: tool_tip
{tool_block(plan)}{guide_block()}"""


def _for_profile(plan: Plan) -> str:
    """The driver profile's wrench: its topic, frame, model (who removes the tool's weight), sign and rate."""
    d = plan.driver
    command = command_line(plan.spec)
    mass = num(plan.spec.tool_mass)
    model = model_words(d)
    if d.payload_compensated:
        tool = comment(
            f"The driver's wrench is {model}. Set the tool ({mass} kg, centre of mass [0.0, 0.0, 0.05] m in the "
            "sensor frame) as the payload configured on the robot: the wrench then excludes its weight in any "
            "orientation, and compensating it here as well would subtract the weight twice."
        ) + "tool_mass: 0                        # [kg]\ntool_com: [0.0, 0.0, 0.0]           # [m]\n"
    else:
        tool = comment(
            f"The driver's wrench is {model}: the tool of config/description.args is compensated here with the "
            "sensor's orientation."
        ) + f"tool_mass: {mass}                      # [kg]\ntool_com: [0.0, 0.0, 0.05]          # [m] in the sensor frame\n"
    zero = f" (or call {d.zero_service})" if d.zero_service else ""
    sign = ""
    if d.wrench_sign < 0:
        sign = comment(
            "The driver reports the wrench the robot exerts on the environment, the opposite of the wrench on the "
            "tool (the profile's wrench.sign -1): all three sensor axes flip, force and torque."
        ) + "ft_x_direction: -1\nft_y_direction: -1\nft_z_direction: -1\n"
    header = comment(
        f"contact_control_node settings for a real {plan.spec.name} driven by {d.driver}, reading the driver's "
        f"wrench ({written(d, command)}). Loaded on top of contact_control's defaults by launch/hardware.launch."
    )
    return f"""{header}
ft_in_topic: {d.wrench_topic}                 # the driver's geometry_msgs/WrenchStamped, {d.rate:g} Hz
velocity_out_topic: jog_arm_server/contact_cmds
move_group: manipulator
fixed_frame: {plan.base}
velocity_command_frame: {plan.base}
# The driver stamps its wrench in {d.wrench_frame} ({frame_origin(d)}).
ft_sensor_frame: {d.wrench_frame}
control_frame: {plan.base}
eef_frame: tool_tip
{tool}tare_on_startup: true               # still: a sensor's zero drifts{zero}
{sign}# The filter is rate-true (it measures the rate): designed for the driver's {d.rate:g} Hz until measured.
lp_filter_delta_t: {num(round(1.0 / d.rate, 4))}            # [s]
lp_filter_cutoff_freq: 5.0          # [Hz]
{guide_block()}"""
