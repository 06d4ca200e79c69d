"""A driver profile (`robot_setup.driver`) in words, for the hardware files and the README."""

from __future__ import annotations

from robot_setup.driver import DriverInterface

__all__ = ["MESSAGE", "frame_origin", "model_words", "switch_words", "written"]

# jog_arm's output message for the profile's `command`.
MESSAGE = {"velocity": "std_msgs/Float64MultiArray [rad/s]", "trajectory": "trajectory_msgs/JointTrajectory"}
# The profile's wrench models (mujoco_driver.profiles), in words.
_MODEL_WORDS = {
    "sensor": "the raw wrist sensor's, the tool's weight included",
    "payload_compensated": "payload-compensated: the driver removes the payload set on the robot",
    "external_estimate": "an estimate from the joint torques, net of the load configured on the robot",
}


def model_words(d: DriverInterface) -> str:
    """The wrench model in words (an unknown one by its name)."""
    return _MODEL_WORDS.get(d.wrench_model, d.wrench_model)


def frame_origin(d: DriverInterface) -> str:
    """Where the wrench's frame comes from, in words."""
    for parent, child in d.tf:
        if child == d.wrench_frame:
            return f"on tf from the driver: {parent} -> {child}"
    return "a frame of this description"


def switch_words(d: DriverInterface) -> str:
    stop = f", stopping {', '.join(d.stop_for_jog)}" if d.stop_for_jog else ""
    return f"{d.controller_manager}/switch_controller{stop}"


def written(d: DriverInterface, command: str) -> str:
    return (f"written by make robot from mujoco_driver's {d.profile} profile, `{command}`; run unchanged "
            f"against `emulated_robot.launch robot_package:=<this package> profile:={d.profile}`")
