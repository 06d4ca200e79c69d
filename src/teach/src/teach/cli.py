"""`rosrun teach teach`: hand-guiding, recording and programs from a terminal (the services' answers printed).

    teach guide on [--axes x y z] | off
    teach record NAME [--keep-bag] [--overwrite] [--no-wait]  (Enter: keyframe, q + Enter: stop, save)
    teach keyframe | stop
    teach list | show NAME | delete NAME
"""

from __future__ import annotations

import argparse
import sys
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
    for name, what in (("show", "print a program's YAML"), ("delete", "delete a program")):
        sub.add_parser(name, help=what).add_argument("name")
    return parser


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
