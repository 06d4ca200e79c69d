"""Adding an arm: the checker names what is wrong with a robot package, the generator refuses bad input,
finds a start pose the demos can use, and writes the same files for the same command (the committed
generated packages are exactly what `make robot` writes)."""

from __future__ import annotations

import pathlib
import shutil

import pytest
import yaml
from robot_setup.check import check_package
from robot_setup.generate import RobotSpec, recorded_command

# make robot's searches: after the simulations, not beside them (Makefile, test).
pytestmark = pytest.mark.compute

SRC = pathlib.Path(__file__).resolve().parents[2] / "src"
ROBOT_PACKAGES = sorted(p.name for p in SRC.iterdir() if p.name.endswith("_custom"))


def _generated_command(package: str) -> RobotSpec | None:
    """The `make robot` arguments a generated package records in its README (None: hand-written)."""
    return recorded_command((SRC / package / "README.md").read_text())


GENERATED = [p for p in ROBOT_PACKAGES if _generated_command(p)]


@pytest.mark.parametrize("package", ROBOT_PACKAGES)
def test_every_robot_package_passes_the_checker(package):
    assert check_package(str(SRC / package)) == []


@pytest.fixture
def ur3_copy(tmp_path):
    root = tmp_path / "ur3_custom"
    shutil.copytree(SRC / "ur3_custom", root)
    return root


def _edit(path: pathlib.Path, old: str, new: str) -> None:
    text = path.read_text()
    assert old in text
    path.write_text(text.replace(old, new))


def test_checker_names_a_tool_mass_that_differs_from_the_description(ur3_copy):
    _edit(ur3_copy / "config" / "contact_control.yaml", "tool_mass: 1 ", "tool_mass: 1.5 ")
    (problem,) = check_package(str(ur3_copy))
    assert problem.startswith("tool mass: description.args --tool-mass 1.0 kg, contact_control.yaml")
    assert "tool_mass 1.5 kg: gravity compensation would leave 4.91 N" in problem


def test_checker_names_a_tool_com_that_differs(ur3_copy):
    config = ur3_copy / "config" / "contact_control.yaml"
    _edit(config, "tool_com: [0.0, 0.0, 0.05]", "tool_com: [0.0, 0.0, 0.08]")
    assert any(p.startswith("tool centre of mass") for p in check_package(str(ur3_copy)))


def test_checker_names_a_frame_missing_from_the_description(ur3_copy):
    _edit(ur3_copy / "config" / "jog_arm.yaml", "planning_frame: base_link", "planning_frame: base_lnk")
    assert "jog_arm.yaml planning_frame: frame 'base_lnk' is not in the description (description.args)" in (
        check_package(str(ur3_copy))
    )


def test_checker_names_a_start_pose_near_a_joint_limit(ur3_copy):
    scene = ur3_copy / "config" / "sim.yaml"
    data = yaml.safe_load(scene.read_text())
    _edit(scene, f"elbow_joint: {data['start_pose']['elbow_joint']:.4f}", "elbow_joint: 3.0800")
    problems = check_package(str(ur3_copy))
    assert any(p.startswith("start pose: elbow_joint is 0.062 rad from a limit") for p in problems), problems


def test_checker_names_an_obstacle_the_compliant_move_misses(ur3_copy):
    _edit(ur3_copy / "config" / "sim.yaml", "position: [0.366,", "position: [0.566,")
    problems = check_package(str(ur3_copy))
    assert any(p.startswith("compliant_move_z: the obstacle") and "not under the tool tip" in p
               for p in problems), problems


def test_checker_names_demo_motions_jog_arm_would_slow(ur3_copy):
    jog = ur3_copy / "config" / "jog_arm.yaml"
    threshold = yaml.safe_load(jog.read_text())["singularity_threshold"]
    _edit(jog, f"singularity_threshold: {threshold:g}\n", "singularity_threshold: 9\n")
    problems = check_package(str(ur3_copy))
    assert any("jog_arm.yaml singularity_threshold 9: the demos' motions reach condition number" in p
               for p in problems), problems


def test_generator_refuses_an_unknown_flange_and_names_the_links():
    from robot_setup.generate import GeneratorError, RobotSpec, plan_robot

    with pytest.raises(GeneratorError, match=r"TIP='flange' is not a link of .*links: \[.*'tool0'"):
        plan_robot(RobotSpec("ur3", "ur_description/urdf/ur3_robot.urdf", "flange"), log=lambda _: None)
    with pytest.raises(GeneratorError, match=r"URDF=nowhere\.urdf: neither a file nor a path"):
        plan_robot(RobotSpec("x", "nowhere.urdf", "tool0"), log=lambda _: None)
    with pytest.raises(GeneratorError, match="NAME='UR-3'"):
        plan_robot(RobotSpec("UR-3", "ur_description/urdf/ur3_robot.urdf", "tool0"), log=lambda _: None)


@pytest.mark.parametrize("package", GENERATED)
def test_make_robot_writes_the_committed_package_again(package, tmp_path):
    """Reproducible: the same command gives the same files (the start pose search included)."""
    from robot_setup.generate import plan_robot, write_package

    spec = _generated_command(package)
    assert spec is not None
    root = pathlib.Path(write_package(plan_robot(spec, log=lambda _: None), str(tmp_path)))
    written = sorted(p.relative_to(root) for p in root.rglob("*") if p.is_file())
    committed = sorted(p.relative_to(SRC / package) for p in (SRC / package).rglob("*") if p.is_file())
    assert written == committed
    for rel in written:
        assert (root / rel).read_text() == (SRC / package / rel).read_text(), rel


@pytest.mark.parametrize(
    ("hand_written", "urdf", "tip", "removed", "base"),
    [
        ("ur5_custom", "ur_description/urdf/ur5_robot.urdf", "tool0", (), "base_link"),
        ("panda_custom", "panda_description/urdf/panda.urdf", "panda_link8", ("panda_hand",), "panda_link0"),
    ],
    ids=["ur5", "panda"],
)
def test_generator_does_for_the_hand_written_arms_what_their_packages_do(
    hand_written, urdf, tip, removed, base, tmp_path
):
    """What ur5_custom and panda_custom do by hand, the generator does for their arms: the same base frame,
    the gripper below the flange removed, the same thesis-sized demos (0.30 m hybrid travel, obstacle 7 cm
    below the tip, compliant move at most 0.15 m), a tool-down start pose whose demo motions stay below the
    hand-written singularity threshold (8), and a package the checker accepts."""
    from robot_setup.generate import RobotSpec, plan_robot, write_package

    plan = plan_robot(RobotSpec(f"{hand_written[:-7]}gen", urdf, tip), log=lambda _: None)
    hand = yaml.safe_load((SRC / hand_written / "config" / "demos.yaml").read_text())
    # The force limit a real driver's sensor needs is the robot package's (panda_custom: franka_ros 1.5 N).
    assert hand.pop("contact_force", {"limit": 0.5})["limit"] == 0.5
    # Where the curved path runs over the cylinder is measured per arm (its demos.yaml says why), not planned.
    hand.pop("curved_surface", None)
    assert plan.geometry.contact_force_limit == 0.5
    assert plan.geometry.as_dict() == {
        section: {k: v if k == "direction" else float(v) for k, v in values.items()}
        for section, values in hand.items()
    }
    assert plan.gap == pytest.approx(0.07)
    assert plan.start.worst_condition < 8.0
    assert (plan.base, plan.removed) == (base, removed)
    assert check_package(write_package(plan, str(tmp_path))) == []


def test_a_demo_the_arm_cannot_do_is_named_with_the_reason(ur3_copy):
    """What `make demo` prints as [CANNOT] before launching: the hybrid travel beyond the arm's reach."""
    from robot_setup.check import problems_by_demo

    _edit(ur3_copy / "config" / "demos.yaml", "travel: 0.22", "travel: 0.6")
    general, per_demo = problems_by_demo(check_package(str(ur3_copy)))
    assert general == []
    assert list(per_demo) == ["hybrid"]
    expected = "the tool-tip motion (-0.620, +0.000, +0.000) m is not reachable from the start pose"
    assert expected in per_demo["hybrid"][0]


def test_checker_names_the_joint_whose_servo_cannot_hold_the_start_pose(ur3_copy, tmp_path):
    """The URDF's wrist efforts weakened to 0.2 Nm: the kinematic checks pass, but in the simulation the
    tool's weight bends a wrist joint down (make demo would stop at its first named pose); the checker says
    which joint and why."""
    from control_stack.description import find_example_robot_data

    stock = pathlib.Path(find_example_robot_data()) / "robots/ur_description/urdf/ur3_robot.urdf"
    text = stock.read_text()
    assert text.count('effort="54.0"') == 3  # wrist 1-3
    weak = tmp_path / "weak_ur3.urdf"
    weak.write_text(text.replace('effort="54.0"', 'effort="0.2"'))
    stock_source = "example-robot-data:robots/ur_description/urdf/ur3_robot.urdf"
    _edit(ur3_copy / "config/description.args", stock_source, str(weak))
    (problem,) = check_package(str(ur3_copy))
    assert problem.startswith("named pose 'start': the simulated arm ends"), problem
    assert "at wrist_" in problem and "effort limit, 0.2 Nm" in problem


def test_a_tip_no_mounting_fits_takes_the_link_fixed_below_it_as_the_flange():
    """The Unitree Z1 at TIP=link06: a tool across link06 touches link04 in every posture and along it the
    wrist cannot point it down; a person mounts it on the gripper's stator, fixed 51 mm further out, turned
    90 degrees about x: so does make robot, and it records TIP=gripperStator."""
    from robot_setup.generate import RobotSpec, fixed_below, plan_robot
    from robot_setup.plan import command_line, recorded_command

    said: list[str] = []
    plan = plan_robot(RobotSpec("z1t", "z1_description/urdf/z1.urdf", "link06"), log=said.append)
    assert plan.spec.tip == "gripperStator"
    assert plan.tool_rpy == pytest.approx((1.5708, 0.0, 0.0), abs=1e-3)
    assert any("trying gripperStator, fixed below it" in line for line in said)
    recorded = recorded_command(f"generated by `{command_line(plan.spec)}`: the stock URDF")
    assert recorded is not None and recorded.tip == "gripperStator"
    assert fixed_below(plan.urdf_xml, "tool_tip") == []  # nothing fixed below the generated tip
