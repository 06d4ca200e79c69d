# ruff: noqa: E501  (the template is the file's text: its comment lines keep their length)
"""config/jog_arm_hardware.yaml: jog_arm_server against a real driver, generic or a profile's."""

from __future__ import annotations

from robot_setup.driver import GENERIC_TRAJECTORY_TOPIC, DriverInterface
from robot_setup.plan import Plan, command_line
from robot_setup.templates.driver_text import MESSAGE, switch_words, written
from robot_setup.templates.jog_arm_yaml import chain, thresholds
from robot_setup.templates.text import comment, num

__all__ = ["jog_arm_hardware_yaml"]


def jog_arm_hardware_yaml(plan: Plan) -> str:
    d = plan.driver
    if not d.generic:
        return _for_profile(plan)
    return f"""# jog_arm_server settings for a real {plan.spec.name} (written by make robot for a generic driver, run against
# mujoco_driver's emulated_robot.launch without a profile; set the topics of your driver). Loaded on top of jog_arm's config/jog_arm.yaml by launch/hardware.launch. Units: m, rad, s.

ee_frame_name: tool_tip
planning_frame: {plan.base}
cmd_frame: {plan.base}

joint_topic: joint_states
cmd_in_topic: jog_arm_server/delta_jog_cmds
cmd_out_topic: {GENERIC_TRAJECTORY_TOPIC}   # a joint_trajectory_controller's input
command_in_type: speed_units
command_out_type: trajectory
simu: false

{_pub_period(d)}
incoming_cmd_timeout: 0.1
joint_state_timeout: 0.1
low_pass_filter_coeff: 2.5
{thresholds(plan)}{chain(plan)}"""


def _robot_stop(d: DriverInterface) -> str:
    """jog_arm's watch of the driver's own stops (its README's *Robot stops*), for a profile that has one."""
    head = f"""
# The robot's own stops (jog_arm README, "Robot stops"): {d.driver}'s """
    if d.protective_stop is not None:
        stop = d.protective_stop
        return f"""{head}safety mode and program state.
robot_stop:
  watch:
    - {{topic: {stop.safety_mode_topic}, type: ur_dashboard_msgs/SafetyMode, field: mode,
       running: [1, 2]}}                    # NORMAL, REDUCED
    - {{topic: {stop.program_running_topic}, type: std_msgs/Bool, field: data, running: [true]}}
  recover:                                 # std_srvs/Trigger, called in this order
    - {stop.unlock_service}
    - {stop.play_services[0]}
"""
    if d.reflex is not None and d.reflex.state is not None:
        state = d.reflex.state
        running = ", ".join(str(v) for v in state.running)
        return f"""{head}robot mode.
robot_stop:
  watch:
    - {{topic: {state.topic}, type: {state.type}, field: {state.mode_field},
       running: [{running}]}}
  recover:
    - {{action: {d.reflex.recovery_action}, type: {d.reflex.recovery_type}}}
"""
    return ""


def _pub_period(d: DriverInterface) -> str:
    """jog_arm's cycle for a driver: its filter acts per cycle, so for a velocity controller (which takes the
    newest command each of its periods) a short cycle keeps the lag small, and each cycle starts from the
    measured joints; trajectories stay at 8 ms."""
    if d.jog_command == "velocity":
        # The UR3 on the emulated 125 Hz ur_robot_driver at 8 ms (the driver's period): follower, compliant
        # move and hybrid failed, the axes ringing; at 4 ms they pass.
        return ("pub_period: 0.004                   # [s] shorter than the driver's period: less lag (robot_setup README)\n"
                "integrate_from: measured            # velocities out: each cycle starts from the measured joints (the robot\n"
                "                                    #   moves on over a late cycle; jog_arm README, integrate_from)")
    return "pub_period: 0.008"


def _for_profile(plan: Plan) -> str:
    """The driver profile's joint states, jog controller (and the switch it needs) and rate."""
    d = plan.driver
    command = command_line(plan.spec)
    header = comment(
        f"jog_arm_server settings for a real {plan.spec.name} driven by {d.driver} ({written(d, command)}). "
        "Loaded on top of jog_arm's config/jog_arm.yaml by launch/hardware.launch. Units: m, rad, s."
    )
    if d.switch_needed:
        header += comment(
            f"{d.jog_controller} must be running: the driver starts it {d.jog_initial_state}; switch it on with "
            f"{switch_words(d)}."
        )
    return f"""{header}
ee_frame_name: tool_tip
planning_frame: {plan.base}
cmd_frame: {plan.base}

joint_topic: {d.joint_states_topic}                           # the driver's sensor_msgs/JointState, {d.rate:g} Hz
cmd_in_topic: jog_arm_server/delta_jog_cmds
cmd_out_topic: {d.jog_topic}   # {MESSAGE[d.jog_command]}
command_in_type: speed_units
command_out_type: {d.jog_command_type}
simu: false

{_pub_period(d)}
incoming_cmd_timeout: 0.1
joint_state_timeout: {d.state_timeout:g}              # [s] {num(d.state_timeout * d.rate)} periods of the driver's joint states (at least 0.1 s)
low_pass_filter_coeff: 2.5
{thresholds(plan)}{chain(plan)}{_robot_stop(d)}"""
