"""program_server's private parameters, each declared once (no ROS): `PARAMETERS` validates them at
start-up and generates the README's table."""

from __future__ import annotations

import math
from dataclasses import dataclass

from compliant_common.errors import StackError
from compliant_common.schema import SchemaError, param, schema_of
from compliant_common.typedefs import ParamMap

__all__ = ["PARAMETERS", "TeachSettings", "load_settings"]


class TeachParamError(StackError):
    """A program_server parameter is wrong; the message names it."""


@dataclass(frozen=True)
class TeachSettings:
    """The node's parameters (name, type, default, unit, range, doc declared here)."""

    programs_dir: str = param("~/.ros/compliant_programs", nonempty=True,
                              doc="folder of the programs (`<name>.yaml`) and their bags")
    rate: float = param(50.0, unit="Hz", gt=0.0, le=1000.0, doc="recording rate (samples of the latest "
                        "joint state, tool pose and wrench)")
    position_tolerance: float = param(0.001, unit="m", gt=0.0, doc="waypoints reproduce every sample's "
                                      "position within this (at its time)")
    angle_tolerance: float = param(math.radians(1.0), unit="rad", gt=0.0, doc="... and its orientation")
    base_frame: str = param("", shown_default="contact_control_node's `fixed_frame`",
                            doc="frame of the recorded tool pose (empty: the default)")
    tip_frame: str = param("", shown_default="contact_control_node's `eef_frame`",
                           doc="the recorded tool frame (empty: the default)")
    contact_control_node: str = param("contact_control_node", nonempty=True,
                                      doc="where the frames' defaults, `~guide` and `~events` are")
    joint_states_topic: str = param("joint_states", nonempty=True, doc="sensor_msgs/JointState input")
    wrench_topic: str = param("wrench", nonempty=True, doc="geometry_msgs/WrenchStamped input (the sensor's)")
    robot: str = param("", shown_default="robot_description's robot name",
                       doc="the arm's name in programs; a program of another is refused (empty: the default)")


PARAMETERS = schema_of(TeachSettings)


def load_settings(params: ParamMap) -> TeachSettings:
    """Settings from the node's private parameters.

    Raises:
        TeachParamError: An unknown key or a bad value, named.
    """
    try:
        return PARAMETERS.build(TeachSettings, PARAMETERS.load(params, prefix="~"))
    except SchemaError as err:
        raise TeachParamError(err.named("~")) from None
