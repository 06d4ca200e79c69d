"""make robot on an arm on a linear axis (tests/data/rail_arm.urdf: UR5 kinematics on a 0.9 m rail along x):
the rail as a seventh, redundant joint, or held with HELD=; its servo in N/m, its margins in metres."""

from __future__ import annotations

import pathlib

import pytest
import yaml
from robot_setup.check import check_package
from robot_setup.generate import GeneratorError, RobotSpec, plan_robot

from robot_setup import generate

# make robot's searches: after the simulations, not beside them (Makefile, test).
pytestmark = pytest.mark.compute

RAIL_URDF = str(pathlib.Path(__file__).resolve().parents[1] / "data" / "rail_arm.urdf")


def _make(tmp_path: pathlib.Path, name: str, *options: str, exit_code: int = 0) -> pathlib.Path:
    assert generate.main(["--name", name, "--urdf", RAIL_URDF, "--tip", "tool0", "--src", str(tmp_path),
                          *options]) == exit_code
    return tmp_path / f"{name}_custom"


def _yaml(package: pathlib.Path, name: str) -> dict:
    return yaml.safe_load((package / "config" / name).read_text())


def test_a_free_rail_is_a_joint_of_the_arm_with_its_servo_in_newtons_per_metre(tmp_path):
    package = _make(tmp_path, "railfree")
    sim = _yaml(package, "sim.yaml")
    assert "rail_joint" in sim["start_pose"] and not sim.get("held_joints")
    assert sim["servo"]["kp"]["rail_joint"] == pytest.approx(20000.0)  # 1000 N of effort, the rule's clamp
    assert "rail_joint (prismatic): the same numbers in N/m" in (package / "config" / "sim.yaml").read_text()
    assert check_package(str(package)) == []
    # A null-space pull jog_arm would refuse is named (a hand edit: the rail's name misspelt)
    jog_yaml = package / "config" / "jog_arm.yaml"
    jog_yaml.write_text(jog_yaml.read_text() + "nullspace_joints: [rail]\nnullspace_posture: [0.0, 0.0]\n")
    assert check_package(str(package)) == [
        "jog_arm.yaml nullspace_joints: ['rail'] are not the arm's joints ['rail_joint', "
        "'shoulder_pan_joint', 'shoulder_lift_joint', 'elbow_joint', 'wrist_1_joint', 'wrist_2_joint', "
        "'wrist_3_joint']",
        "jog_arm.yaml nullspace_posture: 2 values for the arm's 7 joints"]


def test_a_held_rail_stays_where_held_and_the_arm_has_six_joints(tmp_path):
    package = _make(tmp_path, "railheld", "--held", "rail_joint=0")
    sim, jog = _yaml(package, "sim.yaml"), _yaml(package, "jog_arm.yaml")
    assert sim["held_joints"] == [{"rail_joint": 0.0}] and jog["held_joints"] == [{"rail_joint": 0.0}]
    assert "rail_joint" not in sim["start_pose"] and "rail_joint" not in jog["joint_names"]
    assert len(jog["joint_names"]) == 6
    assert check_package(str(package)) == []


def test_a_start_pose_whose_forearm_rests_on_the_obstacle_is_refused_by_the_check(tmp_path):
    """Held at 0.2 m, the start pose search picks a flipped posture (shoulder lift 3.07 rad) whose forearm
    lies on the block placed under the tool after the search; the demonstrations dragged it (follower_z
    2.4 mm sideways, the replay and peg in hole failed): the check's simulation names the link."""
    package = _make(tmp_path, "railrest", "--held", "rail_joint=0.2", exit_code=1)  # make robot's own check
    assert check_package(str(package)) == [
        "start pose: the simulated arm's forearm_link rests on the table or the obstacle there (the "
        "demonstrations would drag it along)"]


def test_only_a_linear_axis_of_the_arm_can_be_held():
    spec = RobotSpec("t", RAIL_URDF, "tool0", held=(("elbow_joint", 0.0),))
    with pytest.raises(GeneratorError, match=r"HELD=elbow_joint: elbow_joint is an arm joint .* only a "
                                             r"linear axis \(a prismatic joint, a rail\) can be held"):
        plan_robot(spec, log=lambda _: None)

