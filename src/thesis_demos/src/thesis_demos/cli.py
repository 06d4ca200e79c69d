"""`rosrun thesis_demos run_demos`: the thesis demonstrations (and two more) against a running stack."""

from __future__ import annotations

import argparse
import math
import os
import sys
import time
from collections.abc import Sequence
from typing import Any

from contact_control.noise_floor import NoiseFloor
from contact_control.params import ContactControlSettings

from thesis_demos.scenarios import SURFACE_TOLERANCE

__all__ = ["main", "unresolvable"]

#: The report's sections as data, which a second run (--append) adds to.
REPORT_DATA = "report.yaml"

#: run_demos' exit status when nothing failed but some demonstrations cannot be done ([CANNOT]).
EXIT_CANNOT = 3

#: Raw noise stds on top of a push that must stay under the global limit (latched on 2 wrenches in a row).
PUSH_NOISE_SIGMAS = 3.0

#: The force tracking's input wanders this many filtered noise stds either way (95 % of the time).
TRACKING_NOISE_SIGMAS = 2.0


def _args(argv: Sequence[str]) -> argparse.Namespace:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--output", default="demo_output", help="folder for plots and report.md")
    parser.add_argument(
        "--robot",
        default="",
        help="robot name: its package <robot>_custom gives the demos' geometry (config/demos.yaml) and the "
        "obstacle (config/sim.yaml); empty: the thesis-sized defaults, no preflight",
    )
    parser.add_argument("--demos-config", default="", help="a demos.yaml instead of the robot package's")
    parser.add_argument("--only", nargs="*", help="run only these demos (follower_z compliant_move_z ...)")
    parser.add_argument("--sensor-frame", default="ft_sensor")
    parser.add_argument("--wrench-topic", default="wrench", help="the wrist wrench (a real driver's topic)")
    parser.add_argument("--driver", default="", help="the driver profile behind the stack (demos.yaml's "
                        "contact_force.drivers may set its force limit)")
    parser.add_argument("--base-frame", default="", help="default: contact_control's ~fixed_frame")
    parser.add_argument("--timeout", type=float, default=60.0, help="seconds to wait for the stack")
    parser.add_argument("--tasks", default="task_server", help="contact_tasks' task_server (peg in hole)")
    parser.add_argument("--append", action="store_true", help="add to the output folder's report (a "
                        "demonstration in a scene of its own, run in a second launch)")
    return parser.parse_args(argv)


def _path_cannot(runner: Any, setup: Any) -> str:
    """Why the curved demonstration cannot run here ("" if it can): no nominal part, or no cylinder."""
    if setup.obstacle is None:
        return "the robot package's scene has no obstacle, whose top is the curved part's nominal place"
    if not runner.has_surface("cylinder"):
        return ("this scene has no cylinder (make demo runs it in a second launch with "
                "fixture:=cylinder tool:=ball and a surface_seed)")
    return ""


def unresolvable(scenario: Any, floor: NoiseFloor | None, sigmas: float,
                 global_force: float = ContactControlSettings.global_max_force,
                 pose: tuple[float, float] = (0.0, 0.0)) -> str:
    """Why the sensor cannot do `scenario` ("" if it can), from contact_control's noise floor, its
    noise_limit_sigmas and global_max_force: a force or torque limit, or a push, below what it resolves; a
    push whose raw noise (PUSH_NOISE_SIGMAS stds) reaches the global limit; or force tracking whose tolerance
    the noise the laws act on (+- TRACKING_NOISE_SIGMAS filtered stds) exceeds."""
    if floor is None or sigmas <= 0.0:
        return ""
    # `pose`: how far the offset moves over the workspace (the bias map's held-out residual or the declared
    # pose offset), counted beside the noise as contact_control counts it.
    force, torque = floor.resolvable(sigmas)
    force, torque = math.hypot(force, sigmas * pose[0]), math.hypot(torque, sigmas * pose[1])
    moving = f" and the offset's change with the pose, {pose[0]:.2g} N," if pose[0] > 0.0 else ""
    resolves = (f"the sensor resolves forces of {force:.2g} N and more (contact_control's noise "
                f"floor{moving} times its noise_limit_sigmas)")
    laws = list(scenario.laws.values())
    if scenario.follow_up:
        laws += list(scenario.follow_up.laws.values())
    for law in laws:
        if 0.0 < law.force_limit < force:
            return (f"{resolves}; this demonstration stops at {law.force_limit:g} N: raise demos.yaml's "
                    "contact_force (drivers: {<profile>: N})")
        if 0.0 < law.torque_limit < torque:
            return (f"the sensor resolves torques of {torque:.2g} Nm and more; this demonstration stops at "
                    f"{law.torque_limit:g} Nm")
    raw = PUSH_NOISE_SIGMAS * max(floor.std[:3])
    for push in scenario.pushes:
        magnitude = math.hypot(*push.force)
        if 0.0 < magnitude < force:
            return f"{resolves}; this demonstration pushes with {magnitude:g} N, within its noise"
        if magnitude + raw > global_force:
            return (f"its {magnitude:g} N push plus the sensor's noise ({PUSH_NOISE_SIGMAS:g} stds: "
                    f"{raw:.2g} N) reaches contact_control's {global_force:g} N global limit "
                    "(global_max_force), which would latch during the push")
    wander = TRACKING_NOISE_SIGMAS * floor.force
    if scenario.tracks_force and wander > SURFACE_TOLERANCE:
        return (f"the force the laws track wanders +-{wander:.2g} N on the sensor's noise alone "
                f"({TRACKING_NOISE_SIGMAS:g} filtered stds), beyond this demonstration's "
                f"+-{SURFACE_TOLERANCE:g} N")
    return ""


def main(argv: Sequence[str] | None = None) -> int:
    import rospy

    argv = rospy.myargv(sys.argv if argv is None else list(argv))[1:]
    args = _args(argv)
    from thesis_demos.analysis import Verdict, judge
    from thesis_demos.finishing import judge_path
    from thesis_demos.geometry import DemoConfigError, robot_setup
    from thesis_demos.insertion import judge_task
    from thesis_demos.path_client import PathFlow
    from thesis_demos.plotting import plot, plot_path, plot_task
    from thesis_demos.report import markdown
    from thesis_demos.runner import DemoRunner, Names
    from thesis_demos.scenarios import by_name, fitted
    from thesis_demos.task_client import TaskFlow

    try:
        setup = robot_setup(args.robot, args.demos_config)
        scenarios = by_name(args.only, setup.geometry.for_driver(args.driver))
    except (DemoConfigError, KeyError) as exc:
        print(f"run_demos: {exc}", file=sys.stderr, flush=True)
        return 2
    print(f"demos' geometry: {setup.source}", flush=True)
    rospy.init_node("thesis_demos", anonymous=True, disable_signals=True)
    os.makedirs(args.output, exist_ok=True)
    started = time.monotonic()
    runner = DemoRunner(Names(base_frame=args.base_frame, wrench=args.wrench_topic), timeout=args.timeout)
    results = []
    cannot: dict[str, str] = {}
    try:
        if setup.checks_scene:
            # Plain words before anything moves: what this arm's start pose and scene do not allow.
            tip = runner.start_tip()
            cannot = setup.preflight(tip)
            scenarios = fitted(setup, scenarios, tip)
            for name, reason in cannot.items():
                if any(s.name == name for s in scenarios):
                    print(f"[CANNOT] {name}: this arm cannot do it as configured: {reason}", flush=True)
        floor = runner.noise_floor()
        sigmas = runner.contact_setting("noise_limit_sigmas")
        global_force = runner.contact_setting("global_max_force")
        pose = runner.pose_residual()
    except (TimeoutError, RuntimeError) as exc:  # the stack never got ready: why, not a traceback
        print(f"run_demos: the stack is not ready for the demonstrations: {exc}", file=sys.stderr, flush=True)
        return 1
    for scenario in scenarios:
        if scenario.name in cannot:
            continue
        reason = unresolvable(scenario, floor, sigmas, global_force, pose)
        if scenario.task is not None and not runner.has_hole():
            reason = ("this scene has no hole fixture (make demo runs it in a second launch with "
                      f"{' '.join(f'{k}:={v}' for k, v in scenario.scene)})")
        if scenario.path is not None and not reason:
            reason = _path_cannot(runner, setup)
        if reason:  # the sensor cannot tell this demonstration's force limit from its noise
            cannot[scenario.name] = reason
            print(f"[CANNOT] {scenario.name}: {reason}", flush=True)
            continue
        png = f"{scenario.name}.png"
        try:
            if scenario.task is not None:
                nominal = setup.obstacle.position[:2] if setup.obstacle is not None else None
                done = TaskFlow(runner, args.tasks, nominal).run(scenario.task, args.sensor_frame)
                verdict = judge_task(scenario.task, done)
                plot_task(scenario, done, verdict, os.path.join(args.output, png))
            elif scenario.path is not None and setup.obstacle is not None:
                flow = PathFlow(runner, args.tasks, setup.obstacle.top_centre)
                ran = flow.run(scenario.path, args.sensor_frame)
                verdict = judge_path(scenario.path, ran)
                plot_path(scenario, ran, verdict, os.path.join(args.output, png))
            else:
                recording = runner.run(scenario, args.sensor_frame)
                verdict = judge(scenario, recording)
                plot(scenario, recording, verdict, os.path.join(args.output, png))
        except (RuntimeError, TimeoutError) as exc:  # a refused request or no answer: the reason
            print(f"[FAIL] {scenario.name}: {exc}", flush=True)
            results.append((scenario, Verdict(False, str(exc), {}), ""))
            continue
        results.append((scenario, verdict, png))
        print(f"[{'PASS' if verdict.passed else 'FAIL'}] {scenario.name}: {verdict.summary}", flush=True)
    runner.close()
    report = os.path.join(args.output, "report.md")
    with open(report, "w") as out:
        out.write(markdown(args.robot or "robot", results, time.monotonic() - started,
                           os.path.join(args.output, REPORT_DATA), args.append))
    print(f"report: {report}", flush=True)
    if not all(v.passed for _, v, _ in results):
        return 1
    return EXIT_CANNOT if any(s.name in cannot for s in scenarios) else 0
