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
    named_poses_node: str = param(
        "named_poses", nonempty=True, doc="where `~move_to_joints` is (the move to a program's start)"
    )
    start_speed_scale: float = param(0.5, gt=0.0, le=1.0, doc="speed_scale of the move to a program's start")
    replay_rate: float = param(
        100.0, unit="Hz", gt=0.0, le=1000.0, doc="rate of the path reference streamed to contact_control"
    )
    replay_horizon: float = param(
        0.4, unit="s", ge=0.0, le=2.0,
        doc="each path reference carries where the path goes this far ahead, which contact_control "
        "follows when the stream is late, so a stall of the replay does not stop the tool; also the most "
        "the program's clock moves on after a stall. 0: none",
    )
    replay_horizon_step: float = param(
        0.02, unit="s", gt=0.0, doc="the time between the horizon's poses"
    )
    replay_max_speed: float = param(4.0, gt=0.0, doc="the largest speed factor a replay accepts")
    replay_gain: float = param(
        5.0, unit="1/s", gt=0.0,
        doc="the path law's k on the path axes (the reference's velocity is fed forward)",
    )
    replay_damping_linear: float = param(
        0.0, unit="N/(m/s)", ge=0.0,
        doc="the path law's b on X, Y, Z: > 0 lets a push move the tool off the path by F / (b k); 0: stiff",
    )
    replay_damping_angular: float = param(0.0, unit="Nm/(rad/s)", ge=0.0, doc="same on RX, RY, RZ")
    replay_max_path_error: float = param(
        0.03, unit="m", gt=0.0, doc="a path axis this far from the reference ends the replay (PATH_ERROR)"
    )
    replay_limit_fraction: float = param(
        1.0, gt=0.0, le=1.0,
        doc="a replay's timing is planned within this fraction of contact_control's velocity, acceleration "
        "and deceleration limits: faster segments are slowed before they start (1: a motion taught under "
        "those limits replays at its speed; 0.8 slowed it by 20 %)",
    )
    replay_smoothing: float = param(
        0.1, unit="s", ge=0.0,
        doc="the fed-forward velocity is the path's mean over this much replay time either side, so it ramps "
        "instead of stepping at a waypoint (a step jerks the tool: pressing on the simulated block, each "
        "waypoint's step swung the force by 3-4 N)",
    )
    replay_press_smoothing: float = param(
        0.5, unit="s", ge=0.0,
        doc="`replay_smoothing` for a pressed replay: each joint's servo lags a change of speed by its own "
        "time, which moves the tool along the press axis, and on a stiff surface that is force (UR3 on the "
        "simulated block, 50 ms means of the sensor, a busy machine: 0.1 s 8.8-10.9 N, 0.5 s 9.5-10.7 N). "
        "Free replays keep `replay_smoothing`: 0.5 s there put them 3 mm off the path",
    )
    replay_lead: float = param(
        0.03, unit="s", ge=0.0,
        doc="the fed-forward velocity is the path's this far ahead: the command path's latency (jogger, "
        "driver, servo), so the tool slows where the path does instead of overshooting (a guess from the "
        "simulated arms' 20-50 ms); contact_control's `command_latency` when that is longer",
    )
    replay_lag: float = param(
        0.0015, unit="m", gt=0.0,
        doc="while the tool is this far off the reference across the path's direction (cutting a corner), "
        "the "
        "program's clock slows, to a tenth at twice it: the path is kept, the timing gives",
    )
    replay_lag_along: float = param(
        0.01, unit="m", gt=0.0,
        doc="the same for the tool's lag behind the reference (the arm at its velocity or acceleration "
        "limit)",
    )
    replay_max_angle_error: float = param(0.2, unit="rad", gt=0.0, doc="same for rotations")
    replay_press_damping: float = param(
        600.0, unit="N/(m/s)", gt=0.0,
        doc="force tracking b on the press axis: a larger b corrects later where friction turns (the L's "
        "corner; README, *Compliant replay*); 500 rings (contact_control's README, Force tracking)",
    )
    replay_press_approach: float = param(
        0.005, unit="m/s", gt=0.0,
        doc="pressing, the speed toward the contact until it touches (0.01 m/s overshot to 21 N on the "
        "simulated arms: the surface-following demonstration's finding)",
    )
    replay_force_limit: float = param(
        20.0, unit="N", gt=0.0,
        doc="a force over this on a linear axis ends the replay with `replay_exceeded_action`",
    )
    replay_torque_limit: float = param(
        0.0, unit="Nm", ge=0.0,
        doc="same for torques (0: only contact_control's global limit: a press at the tool tip loads the "
        "wrist through its lever)",
    )
    replay_exceeded_action: int = param(
        1, choices=(0, 1, 2),
        doc="after the limit: 0 stop, 1 move_away, 2 gravity_compensation (needs replay damping > 0)",
    )
    press_tolerance: float = param(
        0.1, gt=0.0, lt=1.0,
        doc="pressing, the path starts once the force has stayed within this fraction of press_force for "
        "`press_settle_time`",
    )
    press_settle_time: float = param(0.5, unit="s", ge=0.0, doc="see `press_tolerance`")
    press_timeout: float = param(
        30.0, unit="s", gt=0.0, doc="pressing, no steady contact within this ends the replay"
    )
    settle_time: float = param(0.5, unit="s", ge=0.0, doc="the reference holds the last pose this long")
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
