"""`rosrun contact_control identify_payload`: fit the tool from a CSV of recorded samples, or tilt the live
arm through a few orientations and fit it there (see the package README, "Payload identification")."""

from __future__ import annotations

import argparse
import math
import sys
import time
from collections.abc import Sequence

from contact_control.payload import PayloadError, fit_payload, read_csv_samples

__all__ = ["TILT_PLAN", "main"]

# Orientations to sample, as tilts (about the command frame's X, Y axes) [rad] relative to where the tool
# starts: level, both ways about X and Y, and two diagonals, so gravity moves in two directions across the
# sensor (the centre of mass needs that). Multiplied by --tilt.
TILT_PLAN: tuple[tuple[float, float], ...] = (
    (0.0, 0.0), (1.0, 0.0), (-1.0, 0.0), (0.0, 1.0), (0.0, -1.0),
    (math.sqrt(0.5), math.sqrt(0.5)), (-math.sqrt(0.5), -math.sqrt(0.5)),
)


def _csv(args: argparse.Namespace) -> int:
    try:
        fit = fit_payload(read_csv_samples(args.file, (0.0, 0.0, -args.gravity)))
    except (OSError, PayloadError) as err:
        print(f"identify_payload: {err}", file=sys.stderr)
        return 1
    print(fit.describe())
    print(fit.yaml_keys(), end="")
    if args.output:
        with open(args.output, "w") as out:
            out.write(f"# identify_payload {args.file}: {fit.describe()}\n{fit.yaml_keys()}")
    return 0


def _robot(args: argparse.Namespace) -> int:
    import rospy
    from geometry_msgs.msg import TwistStamped
    from sensor_msgs.msg import JointState
    from std_srvs.srv import Trigger

    rospy.init_node("identify_payload", anonymous=True)
    ns = args.contact_control.rstrip("/") + "/payload/"
    for name in ("add_sample", "identify", "clear"):
        rospy.wait_for_service(ns + name, timeout=30)
    call = {name: rospy.ServiceProxy(ns + name, Trigger) for name in ("add_sample", "identify", "clear")}
    twist_pub = rospy.Publisher(args.twist_topic, TwistStamped, queue_size=1, tcp_nodelay=True)
    speeds: list[float] = []
    rospy.Subscriber(args.joint_states, JointState, lambda m: speeds.append(max(map(abs, m.velocity or [0]))))
    deadline = time.monotonic() + 10
    while twist_pub.get_num_connections() == 0 and time.monotonic() < deadline:
        time.sleep(0.05)  # start-up only: wait for jog_arm to subscribe

    def tilt(dx: float, dy: float) -> None:
        """Turns the tool by (dx, dy) rad about the command frame's X and Y axes, then waits for rest."""
        angle = math.hypot(dx, dy)
        if angle > 0.0:
            msg = TwistStamped()
            msg.header.frame_id = args.frame
            msg.twist.angular.x, msg.twist.angular.y = args.speed * dx / angle, args.speed * dy / angle
            rate = rospy.Rate(50)
            end = rospy.get_time() + angle / args.speed
            while rospy.get_time() < end and not rospy.is_shutdown():
                msg.header.stamp = rospy.Time.now()
                twist_pub.publish(msg)
                rate.sleep()
        # At rest: 0.2 s without joint motion; on a loaded machine the servos jitter, so give up waiting
        # after 10 s (add_sample still refuses a sensor that turns while it samples).
        started = quiet_since = time.monotonic()
        while time.monotonic() - quiet_since < 0.2 and time.monotonic() - started < 10.0:
            if rospy.is_shutdown():
                return
            if speeds and speeds[-1] > 5e-3:
                quiet_since = time.monotonic()
            time.sleep(0.02)

    print(call["clear"]().message)
    at = (0.0, 0.0)
    for tx, ty in TILT_PLAN:
        target = (tx * args.tilt, ty * args.tilt)
        tilt(target[0] - at[0], target[1] - at[1])
        at = target
        for _attempt in range(3):  # a stall of the machine can turn the sensor while it samples
            answer = call["add_sample"]()
            print(answer.message, flush=True)
            if answer.success:
                break
        else:
            return 1
    tilt(-at[0], -at[1])  # back to where it started
    answer = call["identify"]()
    print(answer.message)
    return 0 if answer.success else 1


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="identify_payload", description=__doc__)
    sub = parser.add_subparsers(dest="how", required=True)
    csv_p = sub.add_parser("csv", help="fit from a CSV: fx..tz and r11..r33 or gx, gy, gz, a row per pose")
    csv_p.add_argument("file")
    csv_p.add_argument("--gravity", type=float, default=9.81, help="|g| [m/s^2] for rotation columns")
    csv_p.add_argument("--output", help="also write the YAML keys to this file")
    robot = sub.add_parser("robot", help="tilt the live arm through orientations (jog_arm) and fit there")
    robot.add_argument("--contact-control", default="contact_control_node", help="its node name")
    robot.add_argument("--twist-topic", default="jog_arm_server/delta_jog_cmds")
    robot.add_argument("--joint-states", default="joint_states")
    robot.add_argument("--frame", default="", help="frame of the tilt axes (empty: jog_arm's cmd_frame)")
    robot.add_argument("--tilt", type=float, default=0.4, help="tilt of each pose [rad]")
    robot.add_argument("--speed", type=float, default=0.25, help="angular speed while tilting [rad/s]")
    import rospy

    args = parser.parse_args(rospy.myargv(list(sys.argv[1:] if argv is None else argv)))
    return _csv(args) if args.how == "csv" else _robot(args)
