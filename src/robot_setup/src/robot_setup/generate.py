"""`make robot NAME=<name> URDF=<urdf> TIP=<flange link>`: write the robot package `src/<name>_custom/`.

The package has the shape of the hand-written ones (description arguments, scene, contact_control and
jog_arm settings, named poses, the demos' geometry, launch files, README): only YAML and launch files. The
numbers that depend on the arm are measured here (Pinocchio, `robot_setup.analysis`):

  * the reach, and from it the demonstrations' distances (thesis-sized for arms reaching REFERENCE_REACH
    or more, scaled down below) and the obstacle (under the tool tip, its top `gap` below it);
  * the start pose: tool pointing down over the table, joints away from their limits, the lowest
    condition number along the demos' motions;
  * jog_arm's singularity thresholds from the condition numbers measured along those motions;
  * servo gains from the URDF's joint efforts.

The hardware files (`config/*_hardware.yaml`, `launch/hardware.launch`) are written for a generic
ros_control driver, or with `DRIVER=<profile>` for the real driver a mujoco_driver profile describes
(`robot_setup.driver`: topics, wrench frame, sign and payload handling, controllers, all from the profile's
data). The simulation's files do not depend on the driver.

Reproducible: fixed grids and seeds, rounded numbers, no dates; the same command writes the same files.
"""

from __future__ import annotations

import argparse
import dataclasses
import math
import os
import sys
import xml.etree.ElementTree as ET
from collections.abc import Callable, Sequence
from dataclasses import replace

import numpy as np
import yaml
from compliant_common.errors import StackError
from control_stack.description import (
    ERD_PACKAGE,
    DescriptionError,
    build_description,
    find_example_robot_data,
    read_source,
)
from jog_arm.kinematics import ArmModel
from jog_arm.settings import JogSettings
from thesis_demos.geometry import SURFACE_DIRECTION, SURFACE_TRAVEL, DemoGeometry, demo_motions
from thesis_demos.scenarios import HYBRID_PUSH_DURATION, HYBRID_PUSH_START

from robot_setup import templates
from robot_setup.analysis import (
    LENGTH_SCALE,
    analyse_pose,
    estimate_reach,
    lowest_joint,
    tip_path,
)
from robot_setup.driver import DriverError, driver_interface
from robot_setup.mounting import TOOL_SIZE, Mounter, Mounting, NoMountingError
from robot_setup.plan import (
    GeneratorError,
    Plan,
    RobotSpec,
    command_line,
    parse_held,
    parse_rpy,
    recorded_command,
)
from robot_setup.sensor_limits import contact_force_for
from robot_setup.slide_check import CHATTER_STD, servo_scale
from robot_setup.templates.sim_yaml import sim_yaml
from robot_setup.tip_response import MIN_TIP_ACCELERATION, tip_acceleration

# Plan, RobotSpec, command_line and recorded_command live in robot_setup.plan (the templates read them too);
# named here as well, where the tests and tests/robot_packages import them.
__all__ = ["GeneratorError", "Plan", "RobotSpec", "command_line", "main", "plan_robot", "recorded_command",
           "render", "write_package"]

# Arms whose tool tip reaches this far from the base axis [m] get the thesis-sized demo motions
# (0.30 m hybrid travel, obstacle 7 cm below the tip); shorter arms get them scaled by reach / this. The
# thesis's two arms, with the 0.12 m tool, reach 0.96 and 1.01 m measured this way (tests/robot_setup).
REFERENCE_REACH = 0.9
# When no mounting has a start pose for the demos at that scale, they are tried smaller, by this factor each
# time, down to MIN_SCALE (0.06 m hybrid travel): a small arm's tool-down workspace is smaller than its reach
# says (the SO-100: reach 0.45 m with the 0.12 m tool, start poses only with the demos at 0.28).
SCALE_STEP, MIN_SCALE = 0.75, 0.2
# The hybrid's compliant move on X runs at the thesis's 0.05 m/s unless it would end less than this after its
# push on Z: the Z spring (b/k = 0.3 s) needs ~3 time constants to come back within 2 mm, rounded up. At scale
# 0.38 (the SO-100) the 0.11 m move had ended during the push, Z still 5 mm up; the UR3's 0.22 m is unchanged.
HYBRID_AFTER_PUSH = 0.8  # [s]
# Servo gain per newton-metre of the URDF's joint effort, capped (stiff like an industrial controller).
KP_PER_NM, KP_MAX, KP_MIN = 120.0, 20000.0, 1000.0
KV_RATIO = 0.02  # kv = kp * this [s]
MIN_JOINTS = 5  # jog_arm jogs 3 to 5 (translation first); the start pose search and demos need 6 so far


def _source(urdf: str) -> tuple[str, str]:
    """(make_description's --source, the URDF text)."""
    if os.path.isabs(urdf) or os.path.isfile(urdf):
        path = os.path.abspath(urdf)
        if not os.path.isfile(path):
            raise GeneratorError(f"URDF={urdf}: no such file")
        return path, read_source(path)
    source = f"{ERD_PACKAGE}:robots/{urdf}"
    try:
        return source, read_source(source, find_example_robot_data())
    except DescriptionError as exc:
        raise GeneratorError(
            f"URDF={urdf}: neither a file nor a path under example-robot-data's robots/ ({exc})"
        ) from exc


def _tree(urdf_xml: str) -> tuple[str, dict[str, list[tuple[str, str, ET.Element]]]]:
    """(root link, parent link -> [(child link, joint type, joint element)]).

    Raises:
        GeneratorError: Not XML.
    """
    try:
        robot = ET.fromstring(urdf_xml)
    except ET.ParseError as exc:
        raise GeneratorError(f"the URDF is not XML: {exc}") from exc
    children: dict[str, list[tuple[str, str, ET.Element]]] = {}
    child_links = set()
    for joint in robot.findall("joint"):
        parent_elem, child_elem = joint.find("parent"), joint.find("child")
        if parent_elem is None or child_elem is None:
            raise GeneratorError(f"URDF joint {joint.get('name')!r} lacks its <parent> or <child>")
        parent, child = parent_elem.get("link", ""), child_elem.get("link", "")
        children.setdefault(parent, []).append((child, joint.get("type", ""), joint))
        child_links.add(child)
    roots = [link.get("name", "") for link in robot.findall("link") if link.get("name") not in child_links]
    if len(roots) != 1:
        raise GeneratorError(f"the URDF must have one root link, found {roots}")
    return roots[0], children


def _default_base(root: str, children: dict, urdf_xml: str) -> str:
    """The URDF root, or its only child when the root is a massless 'world' fixed to it (the UR's)."""
    robot = ET.fromstring(urdf_xml)
    link = next(lnk for lnk in robot.findall("link") if lnk.get("name") == root)
    kids = children.get(root, [])
    if link.find("inertial") is None and len(kids) == 1 and kids[0][1] == "fixed":
        return kids[0][0]
    return root


def _chain(children: dict[str, list[tuple[str, str, ET.Element]]], base: str, tip: str) -> list[str]:
    """The movable joints from `base` down to `tip`, in order.

    Raises:
        GeneratorError: `tip` is not below `base`.
    """
    parent = {child: (link, jtype, joint) for link, kids in children.items() for child, jtype, joint in kids}
    joints, link = [], tip
    while link != base:
        if link not in parent:
            raise GeneratorError(f"TIP={tip!r} is not below BASE={base!r}: choose a BASE on the way from "
                                 f"the URDF root to {tip}")
        link, jtype, joint = parent[link]
        if jtype not in ("fixed", "floating", "planar"):
            joints.append(joint.get("name", ""))
    if not joints:
        raise GeneratorError(f"no movable joint between BASE={base!r} and TIP={tip!r}")
    return joints[::-1]


def _held_positions(
    urdf_xml: str, chain: Sequence[str], given: dict[str, float], spec: RobotSpec
) -> tuple[tuple[str, float], ...]:
    """Every movable joint outside the chain and where it is held: HELD's value, else 0 clamped into its
    limits (URDF order).

    Raises:
        GeneratorError: HELD names a joint that is not in the description, or a position outside its limits.
    """
    joints = {j.get("name", ""): j for j in ET.fromstring(urdf_xml).findall("joint")
              if j.get("type") not in ("fixed", "floating", "planar")}
    for name in given:
        if name not in joints:
            raise GeneratorError(f"HELD={name}: not a movable joint of the description (outside the arm: "
                                 f"{[j for j in joints if j not in chain]})")
    held = []
    for name, joint in joints.items():
        if name in chain:
            continue
        limit = joint.find("limit")
        bounded = limit is not None and joint.get("type") != "continuous"
        lo = float(limit.get("lower", "-inf")) if bounded and limit is not None else -math.inf
        hi = float(limit.get("upper", "inf")) if bounded and limit is not None else math.inf
        if name in given:
            if not lo <= given[name] <= hi:
                raise GeneratorError(f"HELD={name}={given[name]:g}: outside its limits [{lo:g}, {hi:g}]")
            value = given[name]
        else:
            value = min(max(0.0, lo), hi)
        held.append((name, round(value, 6)))
    return tuple(held)


def _round(value: float, step: float) -> float:
    return round(round(value / step) * step, 6)


def _demos(scale: float) -> tuple[float, DemoGeometry]:
    """(obstacle gap [m], the demonstrations' numbers) at `scale` of the thesis's."""
    gap = _round(max(0.04, 0.07 * scale), 0.005)
    travel = _round(0.30 * scale, 0.01)
    least = HYBRID_PUSH_START + HYBRID_PUSH_DURATION + HYBRID_AFTER_PUSH  # [s] the hybrid move lasts this
    return gap, DemoGeometry(
        # The follower rises about F/b x 0.8 s (0.13 m at 5 N): less push, less rise on a small arm; above the
        # 2.5 N follower deadband and long enough to reach F/b at contact_control's acceleration.
        follower_push_force=_round(max(3.5, 5.0 * scale), 0.1),
        compliant_max_travel=_round(gap + 0.08, 0.01),
        hybrid_travel=travel,
        hybrid_speed=min(0.05, math.floor(travel / least * 1000.0) / 1000.0),
    )


def fixed_below(urdf_xml: str, tip: str) -> list[str]:
    """The links fixed below `tip` through fixed joints alone, one child at each step, nearest first: where a
    flange's own adapter (a gripper's stator, a tool flange, a wrist sensor) puts a tool further out."""
    _, children = _tree(urdf_xml)
    links, link = [], tip
    while len(children.get(link, [])) == 1 and children[link][0][1] == "fixed":
        link = children[link][0][0]
        links.append(link)
    return links


def plan_robot(spec: RobotSpec, log: Callable[[str], object] = print) -> Plan:
    """Measure the arm and decide every number of its package (see the module docstring). When no mounting on
    TIP has a start pose and the user gave none (TOOL_RPY), the links fixed below TIP are tried as the flange,
    nearest first (the Unitree Z1's link06 -> gripperStator: a tool across link06 touches link04 in every
    posture; TIAGo's arm_7_link -> arm_tool_link).

    Raises:
        GeneratorError: Bad input, or no usable start pose (why, in words).
    """
    try:
        return _plan_robot(spec, log)
    except NoMountingError as exc:
        below = fixed_below(_source(spec.urdf)[1], spec.tip) if spec.tool_rpy is None else []
        if not below:
            raise
        for deeper in below:
            log(f"[robot] no mounting on {spec.tip} ({exc}); trying {deeper}, fixed below it, as the flange "
                f"(TIP={deeper})")
            try:
                return _plan_robot(dataclasses.replace(spec, tip=deeper), log)
            except NoMountingError:
                continue
        raise exc from None


def _plan_robot(spec: RobotSpec, log: Callable[[str], object]) -> Plan:
    name = spec.name
    if not name or not name.replace("_", "").isalnum() or not name[0].isalpha() or name != name.lower():
        raise GeneratorError(f"NAME={spec.name!r}: use lower-case letters, digits and _ (a ROS package name)")
    if not spec.tool_mass > 0:
        raise GeneratorError(f"TOOL_MASS={spec.tool_mass}: must be positive [kg]")
    try:  # before the measuring: a bad DRIVER is named at once
        driver = driver_interface(spec.driver)
    except DriverError as exc:
        raise GeneratorError(str(exc)) from exc
    source, stock = _source(spec.urdf)
    root, children = _tree(stock)
    links = {lnk.get("name", "") for lnk in ET.fromstring(stock).findall("link")}
    if spec.tip not in links:
        raise GeneratorError(f"TIP={spec.tip!r} is not a link of {spec.urdf}; links: {sorted(links)}")
    base = spec.base or _default_base(root, children, stock)
    if base not in links:
        raise GeneratorError(f"BASE={base!r} is not a link of {spec.urdf}; links: {sorted(links)}")
    chain = _chain(children, base, spec.tip)
    # A HELD linear axis between BASE and TIP (a rail under the arm) is locked where HELD says.
    kinds = {joint.get("name", ""): kind for below in children.values() for _, kind, joint in below}
    for name, _ in spec.held:
        if name in chain and kinds[name] != "prismatic":
            raise GeneratorError(f"HELD={name}: {name} is an arm joint (between BASE and TIP={spec.tip}); of "
                                 "those only a linear axis (a prismatic joint, a rail) can be held")
    chain = [j for j in chain if j not in dict(spec.held)]
    removed = tuple(child for child, _, _ in children.get(spec.tip, []))
    rpy = spec.tool_rpy if spec.tool_rpy is not None else (0.0, 0.0, 0.0)
    mounter = Mounter(stock, spec, removed, chain, ())
    urdf_xml = build_description(stock, mounter.tool(rpy), removed)
    held = _held_positions(urdf_xml, chain, dict(spec.held), spec)
    missing = driver.missing_links({lnk.get("name", "") for lnk in ET.fromstring(urdf_xml).findall("link")})
    if missing:
        raise GeneratorError(
            f"DRIVER={spec.driver}: the profile's frames are not in the {name} description (the emulated "
            f"driver would refuse it): {'; '.join(missing)}"
        )
    mounter = Mounter(stock, spec, removed, chain, held)
    urdf_xml, arm, _ = mounter.build(rpy)
    if arm.nv < MIN_JOINTS:
        raise GeneratorError(
            f"{arm.nv} joints between {base} and {spec.tip} ({', '.join(arm.joint_names)}): jog_arm jogs "
            f"arms with 3 or more (translation first), but pointing the tool down over a point takes "
            f"{MIN_JOINTS}, and make robot's start pose and demonstrations need that (robot_setup README)"
        )
    reach = estimate_reach(arm)
    log(f"[robot] {spec.name}: {arm.nv} joints {list(arm.joint_names)}, tool-tip reach ~{reach:.2f} m")
    if held:
        log(f"[robot] held (outside {base} .. {spec.tip}): "
            + ", ".join(f"{j} = {v:g}" for j, v in held))
    log(f"[robot] {driver.summary()}")
    scale = min(1.0, reach / REFERENCE_REACH)
    while True:
        gap, geometry = _demos(scale)
        log(
            f"[robot] demos scaled by {scale:.2f}: hybrid travel {geometry.hybrid_travel:.2f} m along "
            f"{'-' if geometry.hybrid_direction < 0 else '+'}X, obstacle {gap * 100:.1f} cm below the tip, "
            f"compliant move at most {geometry.compliant_max_travel:.2f} m"
        )
        motions = demo_motions(geometry, approach=gap)
        try:
            mounting: Mounting = mounter.search(reach, motions, gap, log)
            break
        except NoMountingError as exc:
            smaller = scale * SCALE_STEP
            if exc.hopeless or smaller < MIN_SCALE:
                if scale < min(1.0, reach / REFERENCE_REACH):
                    raise NoMountingError(f"{exc} (demos scaled down to {scale:.2f})", exc.hopeless) from exc
                raise
            log(f"[robot] no start pose for the demos at this scale: trying them smaller (a tool-down "
                f"workspace smaller than the reach: {exc})")
            scale = smaller
    if spec.driver:  # written into demos.yaml by the templates
        force = contact_force_for(spec.driver, geometry.contact_force_limit)
        log(f"[robot] demos' contact force with {spec.driver}: {force.limit:g} N ({force.comment()})")
    rpy, urdf_xml, arm, contacts, found = (mounting.rpy, mounting.urdf_xml, mounting.arm, mounting.contacts,
                                           mounting.found)
    adapter = mounting.adapter
    q0 = np.round(found.q, 4)  # what the files say, analysed again as written
    start = analyse_pose(arm, q0, motions, contacts=contacts)
    tip = start.tip
    x, y, z = (float(v) for v in arm.frame_pose(q0, arm.tip_frame, base).translation)
    tip_in_base = (x, y, z)
    worst = start.worst_condition
    threshold = max(6.0, math.ceil(worst * 1.2 * 2.0) / 2.0)
    hard_stop = float(max(12.0, math.ceil(threshold * 1.5)))
    top = float(tip[2] - gap)
    # Wide enough for surface following: the tool, centred on the block, slides SURFACE_TRAVEL on its top.
    slide = 2.0 * (SURFACE_TRAVEL + TOOL_SIZE[0]) + 0.01
    footprint = _round(max(0.10, 0.15 * scale, slide), 0.01)
    obstacle_size = (footprint, footprint, _round(top, 0.001))
    obstacle_position = (_round(tip[0], 0.001), _round(tip[1], 0.001), _round(top / 2.0, 0.0005))
    # Home: the start pose lifted 0.1 m (scaled), clear of the obstacle.
    lift = analyse_pose(arm, q0, {"home": [(0.0, 0.0, 0.1 * scale)]})
    path, ok = tip_path(arm, q0, (0.0, 0.0, 0.1 * scale))
    home = np.round(path[-1], 4) if ok and lift.reachable else q0
    efforts, linear = [], []
    robot = ET.fromstring(urdf_xml)
    servo_joints = (*arm.joint_names, *(j for j, _ in held))
    for name in servo_joints:
        joint = next(j for j in robot.findall("joint") if j.get("name") == name)
        limit = joint.find("limit")
        efforts.append(float(limit.get("effort", 0.0)) if limit is not None else 0.0)
        linear.append(joint.get("type") == "prismatic")
    # The same rule for a prismatic joint, in N/m per N (a rail's 1000 N: 20000 N/m; robot_setup README).
    kp = tuple(_round(min(KP_MAX, max(KP_MIN, KP_PER_NM * e)), 100.0) if e > 0 else KP_MIN for e in efforts)
    kv = tuple(_round(k * KV_RATIO, 1.0) for k in kp)
    armature = 0.2 if max(efforts) > 100.0 else 0.1
    per_joint = tip_acceleration(arm, q0, 1.0)  # [m/s^2 per rad/s^2]
    acceleration = max(JogSettings.default_max_acceleration,
                       math.ceil(MIN_TIP_ACCELERATION / per_joint * 2.0) / 2.0)
    log(f"[robot] jog_arm: joint acceleration limit {acceleration:g} rad/s^2, the tip at least "
        f"{acceleration * per_joint:.2f} m/s^2 along X, Y and Z at the start pose")
    plan = Plan(
        spec=spec, source=source, removed=removed, base=base, tool_rpy=rpy, adapter=adapter, held=held,
        servo_joints=servo_joints,
        linear=tuple(n for n, lin in zip(servo_joints, linear, strict=True) if lin),
        urdf_xml=urdf_xml, joints=arm.joint_names,
        reach=reach, geometry=geometry, gap=gap, obstacle_size=obstacle_size,
        obstacle_position=obstacle_position, start=start, tip_in_base=tip_in_base, home=home,
        threshold=threshold, hard_stop=hard_stop,
        kp=kp, kv=kv, armature=armature, efforts=tuple(efforts), driver=driver, acceleration=acceleration,
    )
    plan = _settle_servos(plan, log)
    for line in analysis_lines(plan, arm):
        log(f"[robot] {line}")
    return plan


def _settle_servos(plan: Plan, log: Callable[[str], object]) -> Plan:
    """The servo gains lowered (kp and kv alike) until the tool slides cleanly on the block
    (`robot_setup.slide_check`); the plan as it was when it does at the effort rule's gains."""
    scene = yaml.safe_load(sim_yaml(plan))
    scale, first, taken = servo_scale(plan.urdf_xml, scene, plan.joints, SURFACE_DIRECTION, KP_MIN)
    if scale == 1.0:
        if math.isnan(first.std):  # never pressed
            log("[robot] sim: the slide check never pressed the tool on the block: servo gains as the rule "
                "gives them")
        elif not first.clean:
            log(f"[robot] sim: the tool chatters on the block while sliding (force std {first.std:.2f} N, "
                f"over {CHATTER_STD:g}) at every servo gain down to kp {KP_MIN:g}: surface following may "
                "fail")
        return plan
    kp = tuple(_round(k * scale, 100.0) for k in plan.kp)
    kv = tuple(_round(k * KV_RATIO, 1.0) for k in kp)
    note = (f"x{scale:g}: at the effort rule's gains the tool chattered on the block while sliding (force "
            f"std {first.std:.2f} N, {taken.std:.2f} N now; robot_setup.slide_check)")
    log(f"[robot] sim: servo gains {note}")
    return replace(plan, kp=kp, kv=kv, servo_note=note)


def analysis_lines(plan: Plan, arm: ArmModel | None = None) -> list[str]:
    """The start pose analysis in words (printed by the generator, written into the README)."""
    s = plan.start
    finite = [(n, m) for n, m in zip(plan.joints, s.margins, strict=True) if math.isfinite(m)]
    closest = min(finite, key=lambda nm: nm[1]) if finite else ("(all continuous)", math.inf)
    names = arm.joint_names if arm is not None else ()
    linear = closest[0] in names and arm is not None and arm.prismatic[names.index(closest[0])]
    margin = f"{closest[1] * LENGTH_SCALE:.3f} m" if linear else f"{closest[1]:.2f} rad"
    lines = [
        f"start pose: tool pointing down, tool tip at ({plan.tip_in_base[0]:.3f}, {plan.tip_in_base[1]:.3f}, "
        f"{plan.tip_in_base[2]:.3f}) m in {plan.base}; condition number {s.condition:.2f} (length scale "
        f"{LENGTH_SCALE} m)",
        f"joint-limit margin at the start pose {margin} ({closest[0]}), at least "
        f"{s.min_margin:.2f} rad "
        "on the demos' motions",
    ]
    if arm is not None:
        lines.append(f"lowest joint origin {lowest_joint(arm, s.q):.3f} m over the table")
    for demo, reports in s.paths.items():
        for p in reports:
            lines.append(
                f"  {demo}: tip motion ({p.offset[0]:+.3f}, {p.offset[1]:+.3f}, {p.offset[2]:+.3f}) m: "
                f"{'reachable' if p.reachable else 'NOT reachable'}, condition <= {p.worst_condition:.2f}, "
                f"margin >= {p.min_margin:.2f} rad"
            )
    lines.append(
        f"jog_arm: singularity_threshold {plan.threshold:g} (1.2 x the worst {s.worst_condition:.2f}, "
        "so the demos "
        f"run unscaled), hard_stop_singularity_threshold {plan.hard_stop:g}"
    )
    return lines


def render(plan: Plan) -> dict[str, str]:
    """The package's files: relative path -> text."""
    return templates.render(plan, analysis_lines(plan))


def write_package(plan: Plan, src_dir: str) -> str:
    """Write `src_dir/<name>_custom/`; returns its path. Existing files of the same names are replaced."""
    root = os.path.join(src_dir, f"{plan.spec.name}_custom")
    for rel, text in render(plan).items():
        path = os.path.join(root, rel)
        os.makedirs(os.path.dirname(path), exist_ok=True)
        with open(path, "w", encoding="utf-8") as handle:
            handle.write(text)
    return root


def main(argv: Sequence[str] | None = None) -> int:
    """`make robot`: plan, write, then run the checker on the written package."""
    parser = argparse.ArgumentParser(prog="make robot", description=__doc__.split("\n\n")[0])
    parser.add_argument("--name", required=True, help="robot name: the package is <name>_custom")
    parser.add_argument(
        "--urdf", required=True, help="URDF path, or a path under example-robot-data's robots/"
    )
    parser.add_argument("--tip", required=True, help="flange link the F/T sensor and tool go on")
    parser.add_argument("--base", default="", help="base frame (default: the URDF root)")
    parser.add_argument("--tool-mass", type=float, default=1.0, help="tool mass [kg] (default 1.0)")
    parser.add_argument(
        "--driver", default="", help="the real driver the hardware files are for: a mujoco_driver profile "
        "name (one in mujoco_driver config/profiles) or YAML path (default: a generic ros_control driver)"
    )
    parser.add_argument(
        "--tool-rpy", default="", help="the sensor's mounting on the flange, roll,pitch,yaw [rad] (default: "
        "straight, or an adapter angle found when straight cannot point the tool down)"
    )
    parser.add_argument(
        "--held", default="", help="joint=position,... of joints outside BASE..TIP (default: 0 within limits)"
    )
    parser.add_argument("--src", default=os.path.join(os.getcwd(), "src"), help="workspace src/ directory")
    args = parser.parse_args(argv)
    try:
        rpy = parse_rpy(args.tool_rpy) if args.tool_rpy else None
        held = parse_held(args.held)
    except ValueError as exc:
        print(f"make robot: error: {exc}", file=sys.stderr)
        return 2
    spec = RobotSpec(args.name, args.urdf, args.tip, args.base, args.tool_mass, args.driver, rpy, held)
    try:
        plan = plan_robot(spec)
    except StackError as exc:  # GeneratorError, DescriptionError, the scene's and jog_arm's: one line each
        print(f"make robot: error: {exc}", file=sys.stderr)
        return 2
    root = write_package(plan, args.src)
    print(f"[robot] wrote {root} (run `make build`, then `make demo ROBOT={spec.name}`)")
    from robot_setup.check import check_package, print_report

    problems = check_package(root)
    print_report(root, problems)
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
