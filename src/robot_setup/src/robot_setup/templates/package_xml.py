"""package.xml: the exec dependencies of the launch files."""

from __future__ import annotations

from robot_setup.plan import Plan
from robot_setup.templates.text import generated_by

__all__ = ["package_xml"]


def _stop_messages(plan: Plan) -> str:
    """The message package of the driver's state that jog_arm watches for stops (jog_arm_hardware.yaml)."""
    d = plan.driver
    package = ""
    if d.protective_stop is not None:
        package = "ur_dashboard_msgs"
    elif d.reflex is not None and d.reflex.state is not None:
        package = d.reflex.state.type.split("/")[0]
    return f"\n  <exec_depend>{package}</exec_depend>" if package else ""


def package_xml(plan: Plan) -> str:
    name = plan.spec.name
    return f"""<?xml version="1.0"?>
<package format="2">
  <name>{name}_custom</name>
  <version>1.0.0</version>
  <description>
    {name} configuration for the compliant-control stack ({generated_by(plan.spec).replace('`', '')}): robot
    description arguments (stock URDF + wrist F/T sensor frame + tool), the MuJoCo scene, contact_control,
    jog_arm and named-pose settings, the demonstrations' geometry, and launch files.
  </description>
  <maintainer email="dev@example.com">compliant-control developers</maintainer>
  <license>BSD</license>

  <buildtool_depend>catkin</buildtool_depend>
  <exec_depend>compliant_rviz</exec_depend>
  <exec_depend>contact_control</exec_depend>
  <exec_depend>control_stack</exec_depend>
  <exec_depend>jog_arm</exec_depend>
  <exec_depend>keyboard_publisher</exec_depend>
  <exec_depend>mujoco_driver</exec_depend>
  <exec_depend>named_poses</exec_depend>
  <exec_depend>robot_state_publisher</exec_depend>{_stop_messages(plan)}
  <!-- The URDF and meshes stay where they are ({plan.source}); nothing is copied here. -->
</package>
"""
