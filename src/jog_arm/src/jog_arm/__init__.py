"""jog_arm: Cartesian jogging of a serial arm (twist in, joint commands out), pure Python core.

The modules here import numpy, Pinocchio and compliant_common only; the ROS adapters are
:mod:`jog_arm.node` and :mod:`jog_arm.ros_io`.
"""

from jog_arm.command_state import CommandResult
from jog_arm.filters import LowPassFilter
from jog_arm.jog_calcs import JogCalcs, JogOutput
from jog_arm.kinematics import ArmModel, KinematicsError
from jog_arm.limits import JointLimiter, singularity_scale
from jog_arm.settings import JogSettings, JointLimitOverride, SettingsError
from jog_arm.status import StatusCode
from jog_arm.timing import CycleMonitor

__all__ = [
    "ArmModel",
    "CommandResult",
    "CycleMonitor",
    "JogCalcs",
    "JogOutput",
    "JogSettings",
    "JointLimitOverride",
    "JointLimiter",
    "KinematicsError",
    "LowPassFilter",
    "SettingsError",
    "StatusCode",
    "singularity_scale",
]
