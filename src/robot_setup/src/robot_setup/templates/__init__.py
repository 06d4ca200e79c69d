"""The text of a generated robot package (the shape of the hand-written ones), from a measured `Plan`: one
module per file it writes, `text` and `driver_text` for what they share.

The hardware files (`config/*_hardware.yaml`, `launch/hardware.launch`) and the README follow the plan's
driver (`robot_setup.driver`: generic, or a mujoco_driver profile); the simulation's files are the same for
any driver and name the `make robot` command without `DRIVER=`.
"""

from __future__ import annotations

from robot_setup.plan import Plan
from robot_setup.templates.cmakelists_txt import cmakelists_txt
from robot_setup.templates.contact_control_hardware_yaml import contact_control_hardware_yaml
from robot_setup.templates.contact_control_yaml import contact_control_yaml
from robot_setup.templates.demos_yaml import demos_yaml
from robot_setup.templates.description_args import description_args
from robot_setup.templates.hardware_launch import hardware_launch
from robot_setup.templates.jog_arm_hardware_yaml import jog_arm_hardware_yaml
from robot_setup.templates.jog_arm_yaml import jog_arm_yaml
from robot_setup.templates.keyboard_launch import keyboard_launch
from robot_setup.templates.named_poses_yaml import named_poses_yaml
from robot_setup.templates.package_xml import package_xml
from robot_setup.templates.readme_md import readme_md
from robot_setup.templates.sim_launch import sim_launch
from robot_setup.templates.sim_yaml import sim_yaml
from robot_setup.templates.view_rviz import view_rviz_for

__all__ = ["render"]


def render(plan: Plan, analysis: list[str]) -> dict[str, str]:
    """Relative path -> file text; `analysis`: the start pose analysis lines the README quotes."""
    return {
        "package.xml": package_xml(plan),
        "CMakeLists.txt": cmakelists_txt(plan),
        "config/description.args": description_args(plan),
        "config/sim.yaml": sim_yaml(plan),
        "config/demos.yaml": demos_yaml(plan),
        "config/named_poses.yaml": named_poses_yaml(plan),
        "config/contact_control.yaml": contact_control_yaml(plan),
        "config/contact_control_hardware.yaml": contact_control_hardware_yaml(plan),
        "config/jog_arm.yaml": jog_arm_yaml(plan),
        "config/jog_arm_hardware.yaml": jog_arm_hardware_yaml(plan),
        "config/view.rviz": view_rviz_for(plan),
        "launch/sim.launch": sim_launch(plan),
        "launch/hardware.launch": hardware_launch(plan),
        "launch/keyboard.launch": keyboard_launch(plan),
        "README.md": readme_md(plan, analysis),
    }
