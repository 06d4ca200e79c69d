# ruff: noqa: E501  (the template is the file's text: launch-file docs keep their long lines)
"""launch/sim.launch: the simulated stack (mujoco_driver's sim_stack.launch on this package's config) and named_poses."""

from __future__ import annotations

from robot_setup.driver import GENERIC_TRAJECTORY_TOPIC
from robot_setup.plan import Plan
from robot_setup.templates.text import generated_by, in_namespace

__all__ = ["sim_launch"]


def sim_launch(plan: Plan) -> str:
    name = plan.spec.name
    pkg = f"{name}_custom"
    generated = generated_by(plan.spec, with_driver=False)
    return in_namespace(f"""<?xml version="1.0"?>
<!--
  Simulated {name} compliant-control stack ({generated.replace('`', '')}): robot_description,
  robot_state_publisher, the MuJoCo driver (headless; viewer:=true for its window, viewer:=rviz for RViz), jog_arm_server and
  contact_control_node, and named_poses. Everything generic is in mujoco_driver/launch/sim_stack.launch.
-->
<launch>
  <arg name="viewer" default="false" doc="true: MuJoCo's viewer; rviz: RViz on config/view.rviz (both need a DISPLAY)"/>
  <arg name="start_pose" default="" doc="override of config/sim.yaml's start pose: '[q1, ..., qn]' [rad], URDF joint order"/>
  <arg name="real_time_factor" default="1.0" doc="simulated s per wall s; > 1 or 0 (as fast as possible) need sim_time:=true"/>
  <arg name="sim_time" default="false" doc="simulated time: the driver publishes /clock, /use_sim_time true"/>
  <arg name="with_jog_arm" default="true" doc="start jog_arm_server"/>
  <arg name="with_contact_control" default="true" doc="start contact_control_node"/>
  <arg name="single_process" default="true" doc="contact_control and jog_arm in one process (control_stack_node), one hop less"/>
  <arg name="with_driver" default="true" doc="false: no driver of its own, only its parameters (a cell's one world simulates this robot: mujoco_driver README, Cells)"/>
  <arg name="publish_synchronously" default="true" doc="the driver writes subscribers' sockets in its loop"/>
  <arg name="fixture" default="none" doc="clear: no block; hole: a plate with a square, chamfered hole on the block; hand: a person's hand (ISO/TS 15066) lying on it; free_hand: that hand held in the air in the block's place; tilted: the block's top tilted 15 degrees; cylinder, sphere: a curved part in the block's place (mujoco_driver README, Fixtures)"/>
  <arg name="hole_offset" default="[0.0, 0.0, 0.0]" doc="the hole's offset from its nominal pose '[dx, dy, yaw]' [m, m, rad]"/>
  <arg name="hole_seed" default="-1" doc="&gt;= 0: the hole's offset drawn from this seed instead (within 4 mm and 2 degrees)"/>
  <arg name="hole_tilt" default="[0.0, 0.0]" doc="the hole's axis tilted '[roll, pitch]' [rad] about its own x, then y axis (at most 0.1)"/>
  <arg name="surface_seed" default="-1" doc="&gt;= 0: the tilted, cylinder or sphere fixture's offset drawn from this seed (each of dx, dy, dz within 10 mm)"/>
  <arg name="surface_offset" default="[0.0, 0.0, 0.0]" doc="the tilted, cylinder or sphere fixture's offset from its nominal place '[dx, dy, dz]' [m]"/>
  <arg name="hole_clearance" default="0.0004" doc="[m] the hole's width minus the peg's"/>
  <arg name="tool" default="default" doc="peg: the tool becomes a 10 mm square peg of the same length and mass; ball: its end a hemisphere (curved parts); plate: a 0.5 m square plate hangs below its end (a cell's bimanual holder)"/>
  <arg name="output" default="screen" doc="screen or log"/>

  <include file="$(find mujoco_driver)/launch/sim_stack.launch">
    <arg name="description_args" value="$(find {pkg})/config/description.args"/>
    <arg name="scene_config" value="$(find {pkg})/config/sim.yaml"/>
    <arg name="jog_arm_config" value="$(find {pkg})/config/jog_arm.yaml"/>
    <arg name="contact_control_config" value="$(find {pkg})/config/contact_control.yaml"/>
    <arg name="trajectory_command_topic" value="{GENERIC_TRAJECTORY_TOPIC}"/>
    <arg name="viewer" value="$(arg viewer)"/>
    <arg name="rviz_config" value="$(find {pkg})/config/view.rviz"/>
    <arg name="start_pose" value="$(arg start_pose)"/>
    <arg name="real_time_factor" value="$(arg real_time_factor)"/>
    <arg name="sim_time" value="$(arg sim_time)"/>
    <arg name="with_jog_arm" value="$(arg with_jog_arm)"/>
    <arg name="with_contact_control" value="$(arg with_contact_control)"/>
    <arg name="single_process" value="$(arg single_process)"/>
    <arg name="with_driver" value="$(arg with_driver)"/>
    <arg name="publish_synchronously" value="$(arg publish_synchronously)"/>
    <arg name="fixture" value="$(arg fixture)"/>
    <arg name="hole_offset" value="$(arg hole_offset)"/>
    <arg name="hole_seed" value="$(arg hole_seed)"/>
    <arg name="hole_tilt" value="$(arg hole_tilt)"/>
    <arg name="surface_seed" value="$(arg surface_seed)"/>
    <arg name="surface_offset" value="$(arg surface_offset)"/>
    <arg name="hole_clearance" value="$(arg hole_clearance)"/>
    <arg name="tool" value="$(arg tool)"/>
    <arg name="output" value="$(arg output)"/>
  </include>

  <!-- Named poses (config/named_poses.yaml): /named_poses/move_to through the driver's trajectory input. -->
  <include file="$(find named_poses)/launch/named_poses.launch">
    <arg name="config" value="$(find {pkg})/config/named_poses.yaml"/>
    <arg name="trajectory_topic" value="{GENERIC_TRAJECTORY_TOPIC}"/>
    <arg name="output" value="$(arg output)"/>
  </include>
</launch>
""")
