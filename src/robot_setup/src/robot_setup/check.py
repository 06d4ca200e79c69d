"""`make check-robot ROBOT=<name>`: is a robot package consistent, and can its arm do the demonstrations?

Pure (no ROS master): reads the package's files, builds the description like make_description, and names
every problem found:
  * frames the YAML files name (scene links, jog_arm's and contact_control's frames) missing from the
    description;
  * the tool's mass and centre of mass differing between description.args and contact_control.yaml (and
    contact_control_hardware.yaml, unless it leaves the payload to the vendor driver: tool_mass 0);
  * the start pose outside or near (< 0.15 rad) its joint limits, a joint origin under the table, the arm
    touching itself or the table (MuJoCo's collision check on the simulated scene);
  * the demonstrations' motions (config/demos.yaml) unreachable from the start pose, slowed by jog_arm's
    singularity threshold or stopped by its hard stop;
  * the scene's obstacle not where the compliant move can meet it (thesis_demos' preflight);
  * named poses whose `start` is not the scene's start pose;
  * held joints (outside the arm) that the scene and jog_arm hold at different positions.
The curved demonstration's path (`path_reach`) is followed too; what the arm cannot do there is not a problem
of the package but a [CANNOT] of make demo (`check_package.last_cannot`).
"""

from __future__ import annotations

import argparse
import math
import os
import shlex
import sys
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np
import yaml
from compliant_common.errors import StackError
from contact_control.params import ContactControlSettings
from control_stack.description import (
    DescriptionError,
    ToolSpec,
    _parser,
    build_description,
    find_example_robot_data,
    read_source,
)
from jog_arm.kinematics import ArmModel, KinematicsError
from jog_arm.settings import JogSettings, SettingsError, held_positions
from named_poses.params import NamedPoseSettings
from thesis_demos.geometry import (
    DemoConfigError,
    demo_motions,
    load_geometry,
    load_obstacle,
    preflight,
    tool_radius,
)
from thesis_demos.scenarios import PathDemo

from robot_setup.analysis import LENGTH_SCALE, MIN_JOINT_HEIGHT, MIN_MARGIN, analyse_pose, lowest_joint
from robot_setup.collisions import CollisionChecker
from robot_setup.hold_check import hold_problems
from robot_setup.path_reach import curved_path_reach

__all__ = [
    "DEMOS",
    "check_package",
    "main",
    "print_report",
    "problems_by_demo",
    "read_description_args",
    "tool_payload_problems",
    "tool_spec",
]

DEMOS = ("follower_z", "compliant_move_z", "spring_x", "hybrid")

# jog_arm's own defaults (src/jog_arm/config/jog_arm.yaml is loaded under the robot's file).
_JOG_DEFAULTS = {"singularity_threshold": JogSettings.singularity_threshold,
                 "hard_stop_singularity_threshold": JogSettings.hard_stop_singularity_threshold,
                 "singularity_length_scale": LENGTH_SCALE}


def _yaml(path: str) -> dict:
    with open(path, encoding="utf-8") as handle:
        return yaml.safe_load(handle) or {}


def read_description_args(args_path: str) -> argparse.Namespace:
    """The make_description arguments of a robot package's `config/description.args` (comments allowed).

    Raises:
        OSError: The file cannot be read.
        SystemExit: An argument make_description refuses.
    """
    with open(args_path, encoding="utf-8") as handle:
        words = [w for line in handle for w in shlex.split(line, comments=True)]
    return _parser().parse_args(words)


def tool_spec(args: argparse.Namespace) -> ToolSpec | None:
    """The tool make_description adds for these arguments (None: no tool)."""
    if not args.tool_parent:
        return None
    return ToolSpec(
        parent=args.tool_parent, ft_name=args.ft_name, ft_xyz=tuple(args.ft_xyz), ft_rpy=tuple(args.ft_rpy),
        name=args.tool_name, mass=args.tool_mass, com=tuple(args.tool_com) if args.tool_com else None,
        inertia=tuple(args.tool_inertia) if args.tool_inertia else None, shape=args.tool_shape,
        size=tuple(args.tool_size), tip_name=args.tip_name,
    )


def tool_payload_problems(
    tool: ToolSpec | None, cc: Mapping[str, Any], where: str = "contact_control.yaml"
) -> list[str]:
    """Where contact_control's `tool_mass` / `tool_com` (the YAML `cc`, contact_control's defaults for absent
    keys) differ from the tool the description carries: gravity compensation would leave a force.

    The description (description.args) is the source; the YAML must repeat it.
    """
    if tool is None:
        return []
    problems = []
    cc_mass = cc.get("tool_mass", ContactControlSettings.tool_mass)
    cc_com = cc.get("tool_com", ContactControlSettings.tool_com)
    if not math.isclose(float(cc_mass), tool.mass, abs_tol=1e-9):
        problems.append(
            f"tool mass: description.args --tool-mass {tool.mass} kg, {where} "
            f"tool_mass {cc_mass} kg: gravity compensation would leave "
            f"{abs(tool.mass - float(cc_mass)) * 9.81:.2f} N"
        )
    desc_com = list(tool.com if tool.com is not None else tool.centre())
    if not np.allclose(desc_com, cc_com, atol=1e-6):
        problems.append(
            f"tool centre of mass: description.args --tool-com {desc_com} m, {where} "
            f"tool_com {list(cc_com)} m"
        )
    return problems


def _description(args_path: str) -> tuple[str, argparse.Namespace]:
    args = read_description_args(args_path)
    erd = find_example_robot_data() if args.source.startswith("example-robot-data:") else None
    urdf = build_description(read_source(args.source, erd), tool_spec(args), args.remove_link, erd,
                             args.robot_name)
    return urdf, args


def _nullspace_problems(jog: dict, joints: tuple[str, ...]) -> list[str]:
    """jog_arm.yaml's null-space pull names the arm's joints, and its posture has one value per joint (jog_arm
    would refuse to start otherwise)."""
    problems = []
    unknown = [j for j in jog.get("nullspace_joints") or [] if j not in joints]
    if unknown:
        problems.append(f"jog_arm.yaml nullspace_joints: {unknown} are not the arm's joints {list(joints)}")
    posture = jog.get("nullspace_posture") or []
    if posture and len(posture) != len(joints):
        problems.append(f"jog_arm.yaml nullspace_posture: {len(posture)} values for the arm's {len(joints)} "
                        "joints")
    return problems


def check_package(root: str) -> list[str]:
    """Every problem of the robot package at `root`, in plain words (empty: none).

    The analysis lines (start pose, motions) are appended to `check_package.last_analysis` for printing;
    the demonstrations beyond the thesis's four that the arm cannot do as planned (not a problem of the
    package: make demo says [CANNOT] and leaves them out) go to `check_package.last_cannot`, name -> reason.
    """
    problems: list[str] = []
    info: list[str] = []
    cannot: dict[str, str] = {}
    check_package.last_analysis = info  # type: ignore[attr-defined]
    check_package.last_cannot = cannot  # type: ignore[attr-defined]
    cfg = os.path.join(root, "config")
    try:
        urdf, args = _description(os.path.join(cfg, "description.args"))
    except (OSError, DescriptionError, SystemExit) as exc:
        return [f"config/description.args: cannot build the description: {exc}"]
    try:
        scene = _yaml(os.path.join(cfg, "sim.yaml"))
        jog = {**_JOG_DEFAULTS, **_yaml(os.path.join(cfg, "jog_arm.yaml"))}
        cc = _yaml(os.path.join(cfg, "contact_control.yaml"))
    except (OSError, yaml.YAMLError) as exc:
        return [f"cannot read the package's YAML: {exc}"]
    import pinocchio as pin

    full = pin.buildModelFromXML(urdf)
    named = {
        "sim.yaml links.ft_sensor": scene.get("links", {}).get("ft_sensor", "ft_sensor"),
        "sim.yaml links.tool": scene.get("links", {}).get("tool", "tool"),
        "sim.yaml links.eef": scene.get("links", {}).get("eef", "tool_tip"),
        **{f"jog_arm.yaml {k}": jog.get(k) for k in ("ee_frame_name", "planning_frame", "cmd_frame")},
        **{f"contact_control.yaml {k}": cc.get(k) for k in
           ("fixed_frame", "velocity_command_frame", "ft_sensor_frame", "control_frame", "eef_frame")},
    }
    for where, frame in named.items():
        if not frame:
            problems.append(f"{where}: not set")
        elif not full.existFrame(frame):
            problems.append(f"{where}: frame {frame!r} is not in the description (description.args)")
    # Tool: what the description carries must be what contact_control subtracts (on a real arm too, unless
    # the hardware config leaves the payload to the vendor driver: tool_mass 0).
    problems += tool_payload_problems(tool_spec(args), cc)
    hardware = os.path.join(cfg, "contact_control_hardware.yaml")
    if os.path.exists(hardware):
        cc_hw = _yaml(hardware)
        if float(cc_hw.get("tool_mass", ContactControlSettings.tool_mass)) != 0.0:
            problems += tool_payload_problems(tool_spec(args), cc_hw, "contact_control_hardware.yaml")
    # Start pose, margins, the demos' motions.
    tip = jog.get("ee_frame_name", "tool_tip")
    try:
        held = held_positions(scene.get("held_joints") or [], "sim.yaml held_joints")
        jog_held = held_positions(jog.get("held_joints") or [], "jog_arm.yaml held_joints")
    except SettingsError as exc:
        return [*problems, str(exc)]
    if jog_held != held:
        problems.append(f"held joints: sim.yaml held_joints {held} but jog_arm.yaml held_joints {jog_held} "
                        "(jog_arm would model the arm elsewhere than the driver holds it)")
    try:
        arm = ArmModel(urdf, tip, tuple(jog.get("joint_names") or ()), held_positions=held)
    except KinematicsError as exc:
        return [*problems, f"jog_arm cannot model the arm: {exc}"]
    problems += _nullspace_problems(jog, arm.joint_names)
    start = scene.get("start_pose") or {}
    missing = [j for j in arm.joint_names if j not in start]
    if missing:
        return [*problems, f"sim.yaml start_pose: no angle for joints {missing}"]
    q0 = np.array([float(start[j]) for j in arm.joint_names])
    scale = float(jog["singularity_length_scale"])
    threshold, hard_stop = float(jog["singularity_threshold"]), float(jog["hard_stop_singularity_threshold"])
    try:
        geometry = load_geometry(os.path.join(cfg, "demos.yaml"))
        obstacle = load_obstacle(os.path.join(cfg, "sim.yaml"))
    except DemoConfigError as exc:
        return [*problems, str(exc)]
    tip_xyz = arm.frame_pose(q0, tip).translation
    radius = tool_radius(os.path.join(cfg, "description.args"))
    for demo, reason in preflight(geometry, tip_xyz, obstacle, radius).items():
        if demo in DEMOS:  # the thesis's four; run_demos names the others it cannot run ([CANNOT])
            problems.append(f"{demo}: {reason}")
    gap = None
    if obstacle is not None:
        gap = float(tip_xyz[2] - obstacle.top) if geometry.compliant_direction < 0 else None
    contacts = None
    if np.all((q0 >= arm.lower) & (q0 <= arm.upper)):  # the scene refuses a start pose outside the limits
        try:
            contacts = CollisionChecker(urdf, arm.joint_names, q0, held).contacts
        except StackError as exc:  # the scene mujoco_driver would build refuses the files
            return [*problems, f"sim.yaml: the simulated scene cannot be built: {exc}"]
    report = analyse_pose(arm, q0, demo_motions(geometry, approach=gap), scale, contacts)
    for name, m, lo, hi, q in zip(arm.joint_names, report.margins, arm.lower, arm.upper, q0, strict=True):
        if m < 0:
            problems.append(f"start pose: {name} = {q:.4f} rad is outside its limits [{lo:.4f}, {hi:.4f}]")
        elif m < MIN_MARGIN:
            problems.append(
                f"start pose: {name} is {m:.3f} rad from a limit (at least {MIN_MARGIN} rad wanted)"
            )
    if lowest_joint(arm, q0) < MIN_JOINT_HEIGHT:
        problems.append(f"start pose: a joint origin is {lowest_joint(arm, q0):.3f} m over the table (under "
                        f"{MIN_JOINT_HEIGHT} m)")
    problems += report.problems(hard_stop)
    if report.reachable and report.worst_condition >= threshold:
        problems.append(
            f"jog_arm.yaml singularity_threshold {threshold:g}: the demos' motions reach condition number "
            f"{report.worst_condition:.2f}, so jog_arm would slow them (raise it above that)"
        )
    if obstacle is not None and report.reachable:
        curved = curved_path_reach(arm, q0, obstacle.top_centre, PathDemo.radius, geometry.curved_length,
                                   geometry.curved_middle, PathDemo.speed, threshold, hard_stop, scale)
        if curved.reason:
            cannot["curved_surface"] = curved.reason
        info.append(f"curved_surface's path: condition <= {curved.worst_condition:.2f}, "
                    + (f"[CANNOT] {curved.reason}" if curved.reason else f"lag <= {curved.lag * 1e3:.1f} mm"))
    finite = [m for m in report.margins if math.isfinite(m)]
    info.append(
        f"start pose: tool tip at ({tip_xyz[0]:.3f}, {tip_xyz[1]:.3f}, {tip_xyz[2]:.3f}) m, condition number "
        f"{report.condition:.2f}, joint-limit margin {min(finite) if finite else math.inf:.2f} rad; "
        "demos' motions: "
        f"condition <= {report.worst_condition:.2f} (threshold {threshold:g}, hard stop "
        f"{hard_stop:g}), margin >= "
        f"{report.min_margin:.2f} rad"
    )
    poses_path = os.path.join(cfg, "named_poses.yaml")
    poses: dict = {}
    if os.path.isfile(poses_path):
        named_file = _yaml(poses_path)
        poses = named_file.get("poses") or {}
        named_start = poses.get("start")
        if named_start is None:
            problems.append("named_poses.yaml: no pose 'start' (the demos move there)")
        elif any(abs(float(named_start.get(j, math.nan)) - float(start[j])) > 1e-9 for j in arm.joint_names):
            problems.append("named_poses.yaml: poses.start differs from sim.yaml's start_pose")
        tolerance = float(named_file.get("goal_tolerance", NamedPoseSettings.goal_tolerance))
    else:
        problems.append("config/named_poses.yaml: missing (named poses, the demos' start)")
        tolerance = NamedPoseSettings.goal_tolerance
    if not problems:  # the simulated arm, held there and moved through its named poses (hold_check)
        try:
            problems += hold_problems(urdf, scene, {k: v for k, v in poses.items() if k != "start"},
                                      tolerance)
        except StackError as exc:
            problems.append(f"sim.yaml: the simulated scene cannot be built: {exc}")
    return problems


def problems_by_demo(problems: Sequence[str]) -> tuple[list[str], dict[str, list[str]]]:
    """(problems of the package as a whole, problems of one demonstration by its name).

    A demonstration's problems start with its name (`hybrid: the tool-tip motion ...`); the others (frames,
    tool, start pose) concern every demonstration.
    """
    general: list[str] = []
    per_demo: dict[str, list[str]] = {}
    for problem in problems:
        demo = problem.split(":", 1)[0]
        if demo in DEMOS:
            per_demo.setdefault(demo, []).append(problem.split(":", 1)[1].strip())
        else:
            general.append(problem)
    return general, per_demo


def print_report(root: str, problems: Sequence[str]) -> None:
    """The checker's verdict on stdout."""
    for line in getattr(check_package, "last_analysis", []):
        print(f"[check] {line}")
    if problems:
        print(f"[check] {os.path.basename(root)}: {len(problems)} problem(s):")
        for p in problems:
            print(f"[check]   - {p}")
    else:
        print(f"[check] {os.path.basename(root)}: OK (frames, tool, start pose, demos' reach, named poses "
              "held in simulation)")


def main(argv: Sequence[str] | None = None) -> int:
    """`make check-robot ROBOT=<name>`: exit 1 and name the problems, 0 when none."""
    parser = argparse.ArgumentParser(prog="make check-robot", description=__doc__.split("\n\n")[0])
    parser.add_argument("--robot", required=True, help="robot name: checks the package <robot>_custom")
    parser.add_argument("--path", default="", help="the package's directory (default: found by name)")
    args = parser.parse_args(argv)
    root = args.path
    if not root:
        from thesis_demos.geometry import find_robot_package

        try:
            root = find_robot_package(args.robot)
        except DemoConfigError as exc:
            print(f"make check-robot: {exc}", file=sys.stderr)
            return 2
    problems = check_package(root)
    print_report(root, problems)
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
