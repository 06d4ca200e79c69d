"""`rosrun contact_tasks task check FILE...` (validates, moves nothing, needs no ROS master) and
`rosrun contact_tasks task run NAME|FILE` (task_server's `~execute`, feedback once a second, the result)."""

from __future__ import annotations

import argparse
import pathlib
import sys
from collections.abc import Sequence

from contact_tasks.task import TaskError
from contact_tasks.task_file import load_task_file

__all__ = ["main"]


def _check(files: Sequence[str]) -> int:
    bad = 0
    for name in files:
        try:
            task = load_task_file(name)
        except TaskError as err:
            print(f"REFUSED {err}")
            bad += 1
            continue
        print(f"OK {name}: task '{task.name}', steps {', '.join(task.steps)} (start {task.start})")
    return 1 if bad else 0


def _run(target: str, server: str, timeout: float, overrides: str) -> int:
    import actionlib
    import rospy
    from compliant_control_msgs.msg import ExecuteTaskAction, ExecuteTaskFeedback, ExecuteTaskGoal

    rospy.init_node("task_cli", anonymous=True, disable_signals=False)
    goal = ExecuteTaskGoal(overrides=overrides)
    path = pathlib.Path(target)
    if path.suffix in (".yaml", ".yml") or path.exists():
        try:
            goal.task_yaml = path.read_text(encoding="utf-8")
        except OSError as err:
            print(f"task run: cannot read {target}: {err.strerror}", file=sys.stderr)
            return 2
    else:
        goal.task = target
    client = actionlib.SimpleActionClient(server, ExecuteTaskAction)
    if not client.wait_for_server(rospy.Duration(timeout)):
        print(f"task run: no action server {server} within {timeout:g} s", file=sys.stderr)
        return 2
    last = [0.0]

    def said(fb: ExecuteTaskFeedback) -> None:
        if fb.elapsed - last[0] >= 1.0:
            last[0] = fb.elapsed
            f = fb.wrench.force
            print(f"  {fb.elapsed:5.1f} s  {fb.step}: F ({f.x:.1f}, {f.y:.1f}, {f.z:.1f}) N, "
                  f"depth {fb.depth * 1e3:.1f} mm, radius {fb.search_radius * 1e3:.1f} mm")

    client.send_goal(goal, feedback_cb=said)
    try:
        client.wait_for_result()
    except KeyboardInterrupt:
        client.cancel_goal()
        client.wait_for_result(rospy.Duration(5.0))
    result = client.get_result()
    if result is None:
        print("task run: no result", file=sys.stderr)
        return 2
    times = ", ".join(f"{n} {t:.1f} s" for n, t in zip(result.steps, result.step_times, strict=False))
    print(f"{result.outcome.upper()}: {result.message}")
    if result.steps:
        print(f"  steps: {times}; peak |F| {result.peak_force:.1f} N, |T| {result.peak_torque:.2f} Nm")
    return 0 if result.success else (2 if result.outcome == "refused" else 1)


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="task", description=__doc__.split("\n\n")[0])
    sub = parser.add_subparsers(dest="command", required=True)
    check = sub.add_parser("check", help="validate task files; nothing moves")
    check.add_argument("files", nargs="+")
    run = sub.add_parser("run", help="run a task through task_server")
    run.add_argument("task", help="a task's name in the server's tasks folder, or a task file")
    run.add_argument("--server", default="/task_server/execute", help="the ExecuteTask action")
    run.add_argument("--timeout", type=float, default=10.0, help="seconds to wait for the server")
    run.add_argument("--set", default="", metavar="YAML", help="overrides merged over the task's keys, e.g. "
                     "'{surface: 0.05}'")
    args = parser.parse_args(argv)
    if args.command == "check":
        return _check(args.files)
    return _run(args.task, args.server, args.timeout, args.set)
