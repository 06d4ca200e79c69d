"""`rosrun teach teach`: hand-guiding, recording and programs from a terminal (the services' answers printed).

    teach guide on [--axes x y z] | off
    teach record NAME [--keep-bag] [--overwrite] [--no-wait]  (Enter: keyframe, q + Enter: stop, save)
    teach keyframe | stop
    teach list | show NAME | delete NAME
    teach replay NAME [--speed 0.5] [--press-z 10]   (Ctrl-C cancels)
    teach pause | resume
"""

from __future__ import annotations

import argparse
import sys
import time
from collections.abc import Callable, Sequence

__all__ = ["main"]


def _parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="teach", description="Teach by hand: guide, record, list programs.")
    parser.add_argument("--node", default="teach", help="program_server's name (default: teach)")
    parser.add_argument("--contact-control", default="contact_control_node",
                        help="contact_control's node name (default: contact_control_node)")
    sub = parser.add_subparsers(dest="command", required=True)
    guide = sub.add_parser("guide", help="hand-guiding on or off")
    guide.add_argument("state", choices=("on", "off"))
    guide.add_argument("--axes", nargs="*", default=[], help="axes to guide (default: the node's guide_axes)")
    record = sub.add_parser("record", help="start recording a program")
    record.add_argument("name")
    record.add_argument("--keep-bag", action="store_true", help="also keep a rosbag of the raw stream")
    record.add_argument("--overwrite", action="store_true", help="replace a program of the same name")
    record.add_argument("--no-wait", action="store_true",
                        help="return at once (stop with `teach stop`); else Enter marks a keyframe, q stops")
    sub.add_parser("keyframe", help="mark a keyframe in the running recording")
    sub.add_parser("stop", help="stop the recording and save the program")
    sub.add_parser("list", help="the saved programs")
    replay = sub.add_parser("replay", help="play a program back with compliance (Ctrl-C cancels)")
    replay.add_argument("name")
    replay.add_argument("--speed", type=float, default=1.0, help="the recorded speed times this (default 1)")
    for axis in ("x", "y", "z"):
        replay.add_argument(f"--press-{axis}", type=float, metavar="N", default=None,
                            help=f"press along {axis} with this force [N] (instead of following the path)")
    sub.add_parser("pause", help="pause the running replay (the tool holds its pose)")
    sub.add_parser("resume", help="resume a paused replay")
    for name, what in (("show", "print a program's YAML"), ("delete", "delete a program")):
        sub.add_parser(name, help=what).add_argument("name")
    return parser


def _replay(args: argparse.Namespace, node: str) -> int:
    """Sends the goal, prints the feedback twice a second and the result; Ctrl-C cancels."""
    import actionlib
    import rospy
    from compliant_common.goal_call import GoalCall
    from compliant_control_msgs.msg import ReplayProgramAction, ReplayProgramGoal, ReplayProgramResult

    press = [(axis, getattr(args, f"press_{axis}")) for axis in ("x", "y", "z")
             if getattr(args, f"press_{axis}") is not None]
    if len(press) > 1:
        print("teach: press along one axis at most", file=sys.stderr)
        return 2
    axis, force = press[0] if press else ("", 0.0)
    client = actionlib.ActionClient(f"{node}/replay", ReplayProgramAction)
    if not client.wait_for_server(rospy.Duration(5.0)):
        print(f"teach: {node}/replay: no action server (is the stack running?)", file=sys.stderr)
        return 1
    shown = [0.0]

    def feedback(fb: object) -> None:
        now = time.monotonic()
        if now - shown[0] >= 0.5:
            shown[0] = now
            print(f"{fb.state}: {fb.progress:.0%}, path error {fb.path_error * 1e3:.1f} mm, "  # type: ignore[attr-defined]
                  f"force {fb.force:.1f} N", flush=True)  # type: ignore[attr-defined]

    goal = ReplayProgramGoal(name=args.name, speed=args.speed, press_axis=axis, press_force=force)
    call: GoalCall[object, ReplayProgramResult] = GoalCall(client, goal, feedback_cb=feedback)
    try:
        while not call.wait(0.5) and not rospy.is_shutdown():  # waits in slices: Ctrl-C gets through
            pass
    except KeyboardInterrupt:
        call.cancel()
        call.wait(10.0)
    result = call.result()
    if result is None:
        print("teach: no result from the replay", file=sys.stderr)
        return 1
    for event in result.contacts:
        p = event.pose.pose.position
        print(f"  {event.type_name} at ({p.x:.3f}, {p.y:.3f}, {p.z:.3f}) m: {event.message}")
    print(result.message, file=sys.stdout if result.success else sys.stderr)
    return 0 if result.success else 1


def main(argv: Sequence[str] | None = None) -> int:
    args = _parser().parse_args(sys.argv[1:] if argv is None else argv)
    import rospy
    from compliant_control_msgs.srv import Guide, ListPrograms, ProgramCommand, RecordProgram
    from std_srvs.srv import Trigger

    node, cc = args.node.rstrip("/"), args.contact_control.rstrip("/")

    def call(service: str, kind: type, **fields: object) -> object | None:
        try:
            rospy.wait_for_service(service, timeout=5.0)
            return rospy.ServiceProxy(service, kind)(**fields)
        except (rospy.ROSException, rospy.ServiceException, OSError) as err:
            print(f"teach: {service}: {err} (is the stack running?)", file=sys.stderr)
            return None

    def answer(response: object | None) -> int:
        if response is None:
            return 1
        ok = bool(response.success)  # type: ignore[attr-defined]
        print(response.message, file=sys.stdout if ok else sys.stderr)  # type: ignore[attr-defined]
        return 0 if ok else 1

    commands: dict[str, Callable[[], int]] = {
        "guide": lambda: answer(call(f"{cc}/guide", Guide, enable=args.state == "on", axes=args.axes)),
        "keyframe": lambda: answer(call(f"{node}/keyframe", Trigger)),
        "pause": lambda: answer(call(f"{node}/pause", Trigger)),
        "resume": lambda: answer(call(f"{node}/resume", Trigger)),
        "replay": lambda: _replay(args, node),
        "stop": lambda: answer(call(f"{node}/stop", Trigger)),
        "show": lambda: answer(call(f"{node}/show", ProgramCommand, name=args.name)),
        "delete": lambda: answer(call(f"{node}/delete", ProgramCommand, name=args.name)),
    }
    rospy.init_node("teach_cli", anonymous=True, disable_signals=True)
    if args.command == "list":
        listed = call(f"{node}/list", ListPrograms)
        if listed is None:
            return 1
        print(f"{len(listed.names)} program(s) in {listed.folder}")  # type: ignore[attr-defined]
        for line in listed.summaries:  # type: ignore[attr-defined]
            print(f"  {line}")
        return 0
    if args.command == "record":
        started = answer(call(f"{node}/record", RecordProgram, name=args.name, keep_bag=args.keep_bag,
                              overwrite=args.overwrite))
        if started or args.no_wait:
            return started
        print("Enter: keyframe; q then Enter (or Ctrl-D): stop and save", flush=True)
        try:
            for line in sys.stdin:
                if line.strip().lower().startswith("q"):
                    break
                answer(call(f"{node}/keyframe", Trigger))
        except KeyboardInterrupt:
            pass
        return answer(call(f"{node}/stop", Trigger))
    return commands[args.command]()
