# ruff: noqa: E501  (the template is the file's text: launch-file docs keep their long lines)
"""launch/keyboard.launch: keyboard jogging on the simulated or the real stack."""

from __future__ import annotations

from robot_setup.plan import Plan

__all__ = ["keyboard_launch"]


def keyboard_launch(plan: Plan) -> str:
    name = plan.spec.name
    pkg = f"{name}_custom"
    return f"""<?xml version="1.0"?>
<!--
  Keyboard jogging of the {name}: the simulated stack (sim.launch, or hardware.launch with hardware:=true) plus
  keyboard_publisher's key_to_twist into jog_arm's input ({plan.base} axes).
-->
<launch>
  <arg name="hardware" default="false" doc="true: real robot (hardware.launch) instead of the simulation"/>
  <arg name="viewer" default="true" doc="open MuJoCo's viewer (simulation only; only if a DISPLAY exists)"/>
  <arg name="launch_prefix" default="" doc="e.g. 'xterm -e' to give key_to_twist a terminal of its own"/>
  <arg name="ns" default="" doc="the robot's namespace (sim.launch's ns)"/>
  <arg name="tf_prefix" default="" doc="the robot's tf prefix (sim.launch's tf_prefix)"/>

  <include unless="$(arg hardware)" file="$(find {pkg})/launch/sim.launch">
    <arg name="viewer" value="$(arg viewer)"/>
    <arg name="ns" value="$(arg ns)"/>
    <arg name="tf_prefix" value="$(arg tf_prefix)"/>
  </include>
  <include if="$(arg hardware)" file="$(find {pkg})/launch/hardware.launch">
    <arg name="ns" value="$(arg ns)"/>
    <arg name="tf_prefix" value="$(arg tf_prefix)"/>
  </include>

  <group ns="$(eval ns or '/')">
    <include file="$(find keyboard_publisher)/launch/keyboard.launch">
      <arg name="topic" value="jog_arm_server/delta_jog_cmds"/>
      <arg name="frame_id" value="{plan.base}"/>
      <arg name="launch_prefix" value="$(arg launch_prefix)"/>
    </include>
  </group>
</launch>
"""
