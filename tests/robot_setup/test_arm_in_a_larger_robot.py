"""An arm that is one branch of a larger robot (TIAGo's arm on its torso, its mobile base and head around it),
or whose URDF carries joints the arm does not control: the generator's BASE .. TIP chain, the held joints,
the sensor mounting (TOOL_RPY, or an adapter angle it picks), and one-line refusals."""

from __future__ import annotations

import math

import numpy as np
import pytest
from control_stack.description import ToolSpec, build_description, find_example_robot_data, read_source
from jog_arm.kinematics import ArmModel, KinematicsError
from robot_setup.collisions import CollisionChecker
from robot_setup.generate import GeneratorError, RobotSpec, main, plan_robot
from robot_setup.plan import command_line, parse_held, parse_rpy, recorded_command

# make robot's searches: after the simulations, not beside them (Makefile, test).
pytestmark = pytest.mark.compute

TIAGO = "tiago_description/robots/tiago_no_hand.urdf"
ARM = tuple(f"arm_{i}_joint" for i in range(1, 8))
AROUND = ("wheel_right_joint", "wheel_left_joint", "torso_lift_joint", "head_1_joint", "head_2_joint")


def _quiet(_line: str) -> None:
    pass


def _tiago(tip: str = "arm_tool_link", rpy=(0.0, 0.0, 0.0)) -> str:
    """TIAGo's description with the sensor and tool on `tip` (mounted at `rpy`)."""
    erd = find_example_robot_data()
    tool = ToolSpec(parent=tip, mass=1.0, com=(0.0, 0.0, 0.05), size=(0.03, 0.12), ft_rpy=rpy)
    return build_description(read_source(f"example-robot-data:robots/{TIAGO}", erd), tool, ("wrist_ft_link",),
                             erd)


def test_the_model_locks_the_joints_outside_the_arm_where_they_are_held():
    """The torso lift is not an arm joint: jog_arm's model holds it where the YAML says, and the tool tip is
    that much higher; a held joint that is also controlled, or not in the URDF, is refused by name."""
    urdf = _tiago()
    low = ArmModel(urdf, "tool_tip", ARM)
    high = ArmModel(urdf, "tool_tip", ARM, held_positions={"torso_lift_joint": 0.2})
    assert low.joint_names == ARM and high.nv == 7
    q = np.zeros(7)
    rise = high.frame_pose(q, "tool_tip").translation - low.frame_pose(q, "tool_tip").translation
    assert rise == pytest.approx([0.0, 0.0, 0.2], abs=1e-9)
    with pytest.raises(KinematicsError, match="held_joints: 'arm_1_joint' is a controlled joint"):
        ArmModel(urdf, "tool_tip", ARM, held_positions={"arm_1_joint": 0.0})
    with pytest.raises(KinematicsError, match="held_joints: 'gripper' is not a joint of the URDF"):
        ArmModel(urdf, "tool_tip", ARM, held_positions={"gripper": 0.0})


def test_collisions_of_parts_the_arm_does_not_move_are_not_the_arms():
    """TIAGo's held wheels stand on the table and its torso column holds the first arm link's mesh in every
    posture: neither is a collision of a start pose. A tool mounted straight on the wrist's centre
    (arm_7_link) sits inside the wrist: that is one."""
    adapter = (0.0, math.pi / 2, 0.0)  # tiago_custom's: the tool along the flange's x axis
    checker = CollisionChecker(_tiago(rpy=adapter), ARM, np.zeros(7), {name: 0.0 for name in AROUND})
    folded = np.array([1.7244, -0.138, 0.7028, 1.1409, -0.2884, 0.7312, 0.6488])
    assert checker.contacts(folded) == []
    inside = CollisionChecker(_tiago("arm_7_link"), ARM, np.zeros(7), {name: 0.0 for name in AROUND})
    assert "arm_5_link / tool" in inside.contacts(folded)


def test_a_tip_that_is_not_below_the_base_is_refused_in_one_line():
    with pytest.raises(GeneratorError, match=r"TIP='wheel_right_link' is not below BASE='torso_lift_link'.*"
                                             r"choose a BASE on the way"):
        plan_robot(RobotSpec("t", TIAGO, "wheel_right_link", base="torso_lift_link"), log=_quiet)


@pytest.mark.parametrize(("held", "message"), [
    ((("arm_3_joint", 0.0),), "HELD=arm_3_joint: arm_3_joint is an arm joint"),
    ((("gripper", 0.0),), r"HELD=gripper: not a movable joint of the description .*'head_1_joint'"),
    ((("torso_lift_joint", 0.9),), r"HELD=torso_lift_joint=0.9: outside its limits \[0, 0.35\]"),
])
def test_held_positions_the_arm_cannot_have_are_refused_by_name(held, message):
    with pytest.raises(GeneratorError, match=message):
        plan_robot(RobotSpec("t", TIAGO, "arm_tool_link", base="torso_lift_link", held=held), log=_quiet)


def test_make_robot_options_are_read_and_recorded_as_given(capsys):
    assert parse_rpy("0,1.5708,0") == (0.0, 1.5708, 0.0)
    assert parse_held("torso_lift_joint=0.1, head_1_joint=-0.2") == (("torso_lift_joint", 0.1),
                                                                      ("head_1_joint", -0.2))
    spec = RobotSpec("t", TIAGO, "arm_tool_link", "torso_lift_link", 1.0, "", (0.0, math.pi / 2, 0.0),
                     (("torso_lift_joint", 0.1),))
    assert recorded_command(f"`{command_line(spec)}`") == RobotSpec(
        "t", TIAGO, "arm_tool_link", "torso_lift_link", 1.0, "", (0.0, round(math.pi / 2, 9), 0.0),
        (("torso_lift_joint", 0.1),))
    for bad in (["--tool-rpy=0,1"], ["--held", "torso_lift_joint"]):
        assert main(["--name", "t", "--urdf", TIAGO, "--tip", "arm_tool_link", *bad]) == 2
        err = capsys.readouterr().err
        assert err.count("\n") == 1 and err.startswith("make robot: error: "), err


def test_a_wrist_no_mounting_fits_takes_the_flange_fixed_below_it():
    """TIAGo's tool on its wrist's centre (arm_7_link) collides with the wrist whatever the adapter; make
    robot says so and takes arm_tool_link, fixed below it, as the flange (the one its README names)."""
    said: list[str] = []
    plan = plan_robot(RobotSpec("t", TIAGO, "arm_7_link", base="torso_lift_link"), log=said.append)
    assert sum("[robot]   adapter" in line for line in said) >= 8  # arm_7_link: straight and every adapter
    (fallback,) = [line for line in said if line.startswith("[robot] no mounting on arm_7_link")]
    assert "nor with the sensor on an adapter at 45 or 90 degrees" in fallback
    assert "trying arm_tool_link, fixed below it" in fallback
    assert plan.spec.tip == "arm_tool_link"


def test_a_file_that_is_not_a_urdf_is_refused_in_one_line(tmp_path, capsys):
    bad = tmp_path / "arm.urdf"
    bad.write_text("<robot name='x'><link name='a'></robot>")
    assert main(["--name", "t", "--urdf", str(bad), "--tip", "a", "--src", str(tmp_path)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith("make robot: error: the URDF is not XML: "), err


def test_a_straight_mounting_near_a_singularity_gets_an_adapter_that_does_better():
    """The UR3 with its tool on ee_link (whose z is across the flange): straight, the demos reach condition
    number 21.6 and touching the block overshot to 26 N; make robot tries the adapters and puts the tool along
    the flange's axis (pitch 90 deg), as on tool0. A user's TOOL_RPY is kept as given."""
    lines: list[str] = []
    urdf = "ur_description/urdf/ur3_gripper.urdf"
    plan = plan_robot(RobotSpec("g", urdf, "ee_link"), log=lines.append)
    assert plan.tool_rpy == pytest.approx((0.0, math.pi / 2, 0.0))
    assert plan.start.worst_condition < 15.0 and "reached condition number 21.6" in plan.adapter
    assert any("trying adapter angles" in line for line in lines)
    given = plan_robot(RobotSpec("g", urdf, "ee_link", tool_rpy=(0.0, 0.0, 0.0)), log=_quiet)
    assert given.tool_rpy == (0.0, 0.0, 0.0) and given.adapter == "" and given.start.worst_condition > 15.0
