# ruff: noqa: E501  (the template is the file's text: launch-file docs keep their long lines)
"""launch/hardware.launch: the stack on the hardware YAML against a real driver, generic or a profile's."""

from __future__ import annotations

from robot_setup.driver import GENERIC_TRAJECTORY_TOPIC
from robot_setup.plan import Plan, command_line
from robot_setup.templates.driver_text import MESSAGE, model_words, switch_words
from robot_setup.templates.text import comment, in_namespace

__all__ = ["hardware_launch"]


def hardware_launch(plan: Plan) -> str:
    if not plan.driver.generic:
        return _for_profile(plan)
    name = plan.spec.name
    header = f"""  {name} compliant-control stack against a real robot (written by make robot for a generic ros_control
  driver; not run on a real arm, but run unchanged against `roslaunch mujoco_driver emulated_robot.launch
  robot_package:={name}_custom`, tests/robot_packages/test_robot_emulated_drivers.py). Start the robot's
  driver first with a joint_trajectory_controller on {GENERIC_TRAJECTORY_TOPIC} and a wrist F/T sensor driver
  publishing WrenchStamped on `wrench`; set other topics in config/*_hardware.yaml.
"""
    return _launch_file(
        f"{name}_custom", header, "start robot_state_publisher for this description", "", "", {
            "trajectory_topic": GENERIC_TRAJECTORY_TOPIC,
        }, "wrench",
    )


def _for_profile(plan: Plan) -> str:
    """The profile's topics, controllers (and the switch jog_arm's needs) and joint-states remap."""
    d = plan.driver
    command = command_line(plan.spec)
    name = plan.spec.name
    pkg = f"{name}_custom"
    if d.switch_needed:
        start = (f"Start {d.driver} first, then switch {d.jog_controller} on ({switch_words(d)}): jog_arm "
                 "commands it, and its commands are ignored until then.")
    else:
        start = f"Start {d.driver} first, with {d.jog_controller} running (jog_arm commands it)."
    remap = ""
    if d.joint_states_topic != "joint_states":
        remap = f"""
  <!-- robot_state_publisher reads the driver's joint states (jog_arm's YAML names its topic). -->
  <remap from="joint_states" to="{d.joint_states_topic}"/>"""
    header = "".join(comment(text, "  ") for text in (
        f"{name} compliant-control stack against a real robot driven by {d.driver} (written by make robot from "
        f"mujoco_driver's {d.profile} profile, {command}; not run on a real arm, but run unchanged against "
        f"`roslaunch mujoco_driver emulated_robot.launch robot_package:={pkg} profile:={d.profile}`, "
        "tests/robot_packages/test_robot_emulated_drivers.py).",
        start,
        f"Expected topics: {d.joint_states_topic} (sensor_msgs/JointState), {d.wrench_topic} "
        f"(geometry_msgs/WrenchStamped, frame {d.wrench_frame}, {model_words(d)}), "
        + (f"{d.jog_topic} ({MESSAGE[d.jog_command]}, jog_arm's and named_poses' output)."
           if d.jog_topic == d.trajectory_topic else
           f"{d.jog_topic} ({MESSAGE[d.jog_command]}, jog_arm's output), {d.trajectory_topic} "
           "(trajectory_msgs/JointTrajectory, named_poses' output)."),
        f"This file loads robot_description ({name} + sensor frame + tool, whose tool_tip jog_arm moves), starts "
        "robot_state_publisher for it, then contact_control and jog_arm in one process (control_stack_node, as "
        "sim.launch; single_process:=false: two nodes) and named_poses. If the driver's "
        "launch runs its own robot_state_publisher on the stock URDF, give it this description instead and pass "
        "with_state_publisher:=false, or the arm's links get two tf publishers.",
    ))
    named_poses = f"""
  <!-- Named poses (config/named_poses.yaml): /named_poses/move_to through the trajectory controller
       ({d.trajectory_topic}), switched on for each move if it is not running (named_poses README). -->"""
    return _launch_file(
        pkg, header,
        "start robot_state_publisher for this description (false if the driver's launch publishes tf from it)",
        remap, named_poses,
        {"trajectory_topic": d.trajectory_topic, "joint_states_topic": d.joint_states_topic}, d.wrench_topic,
    )


def _launch_file(
    pkg: str, header: str, state_publisher_doc: str, remap: str, named_poses_comment: str, named_poses: dict[str, str],
    wrench_topic: str,
) -> str:
    """hardware.launch: `header` (comment lines), the stack on the package's hardware YAML, named_poses with
    the `named_poses` args (a generic driver and a profile's driver differ only in these), RViz on the
    driver's `wrench_topic` with viewer:=rviz."""
    args = "".join(f'\n    <arg name="{key}" value="{value}"/>' for key, value in named_poses.items())
    return in_namespace(f"""<?xml version="1.0"?>
<!--
{header}-->
<launch>
  <arg name="load_description" default="true" doc="load robot_description (false if the driver's launch loads one that has ft_sensor and tool_tip)"/>
  <arg name="with_state_publisher" default="true" doc="{state_publisher_doc}"/>
  <arg name="with_jog_arm" default="true" doc="start jog_arm_server"/>
  <arg name="with_contact_control" default="true" doc="start contact_control_node"/>
  <arg name="single_process" default="true" doc="contact_control and jog_arm in one process (control_stack_node), as sim.launch; false: two nodes, the twist over a topic"/>
  <arg name="with_named_poses" default="true" doc="start named_poses (move_to a pose of config/named_poses.yaml)"/>
  <arg name="viewer" default="false" doc="rviz: RViz on config/view.rviz with the stack's markers (needs a DISPLAY)"/>
  <arg name="bias_map" default="" doc="bias map file of this robot's wrench (control_stack calibrate_bias, contact_control README: Bias map): its pose-dependent offset is subtracted; empty: none"/>
  <arg name="output" default="screen" doc="screen or log"/>
{remap}
  <include file="$(find control_stack)/launch/inc/control_stack.launch.xml">
    <arg name="description_args" value="$(find {pkg})/config/description.args"/>
    <arg name="jog_arm_config" value="$(find {pkg})/config/jog_arm_hardware.yaml"/>
    <arg name="contact_control_config" value="$(find {pkg})/config/contact_control_hardware.yaml"/>
    <arg name="load_description" value="$(arg load_description)"/>
    <arg name="with_state_publisher" value="$(arg with_state_publisher)"/>
    <arg name="with_jog_arm" value="$(arg with_jog_arm)"/>
    <arg name="with_contact_control" value="$(arg with_contact_control)"/>
    <arg name="single_process" value="$(arg single_process)"/>
    <arg name="bias_map" value="$(arg bias_map)"/>
    <arg name="output" value="$(arg output)"/>
  </include>
{named_poses_comment}
  <include if="$(arg with_named_poses)" file="$(find named_poses)/launch/named_poses.launch">
    <arg name="config" value="$(find {pkg})/config/named_poses.yaml"/>{args}
    <arg name="output" value="$(arg output)"/>
  </include>

  <include if="$(eval arg('viewer') == 'rviz')" file="$(find compliant_rviz)/launch/view.launch">
    <arg name="config" value="$(find {pkg})/config/view.rviz"/>
    <arg name="wrench_topic" value="{wrench_topic}"/>
    <arg name="output" value="$(arg output)"/>
  </include>
</launch>
""")
