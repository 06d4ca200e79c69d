"""`rosrun thesis_demos run_demos`: the four thesis demonstrations against a running stack."""

from __future__ import annotations

import argparse
import os
import sys
import time
from collections.abc import Sequence

__all__ = ["main"]


def _args(argv: Sequence[str]) -> argparse.Namespace:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--output", default="demo_output", help="folder for plots and report.md")
    parser.add_argument("--robot", default="robot", help="robot name for the report title")
    parser.add_argument("--only", nargs="*", help="run only these demos (follower_z compliant_move_z ...)")
    parser.add_argument("--sensor-frame", default="ft_sensor")
    parser.add_argument("--wrench-topic", default="/wrench", help="the wrist wrench (a real driver's topic)")
    parser.add_argument("--base-frame", default="", help="default: contact_control's ~fixed_frame")
    parser.add_argument("--timeout", type=float, default=60.0, help="seconds to wait for the stack")
    return parser.parse_args(argv)


def main(argv: Sequence[str] | None = None) -> int:
    import rospy

    argv = rospy.myargv(sys.argv if argv is None else list(argv))[1:]
    args = _args(argv)
    from thesis_demos.analysis import judge
    from thesis_demos.plotting import plot
    from thesis_demos.report import markdown
    from thesis_demos.runner import DemoRunner, Names
    from thesis_demos.scenarios import by_name

    scenarios = by_name(args.only)
    rospy.init_node("thesis_demos", anonymous=True, disable_signals=True)
    os.makedirs(args.output, exist_ok=True)
    started = time.monotonic()
    runner = DemoRunner(Names(base_frame=args.base_frame, wrench=args.wrench_topic), timeout=args.timeout)
    results = []
    for scenario in scenarios:
        recording = runner.run(scenario, args.sensor_frame)
        verdict = judge(scenario, recording)
        png = f"{scenario.name}.png"
        plot(scenario, recording, verdict, os.path.join(args.output, png))
        results.append((scenario, verdict, png))
        print(f"[{'PASS' if verdict.passed else 'FAIL'}] {scenario.name}: {verdict.summary}", flush=True)
    runner.close()
    report = os.path.join(args.output, "report.md")
    with open(report, "w") as out:
        out.write(markdown(args.robot, results, time.monotonic() - started))
    print(f"report: {report}", flush=True)
    return 0 if all(v.passed for _, v, _ in results) else 1
