"""`rosrun control_stack calibrate_bias`: move the arm at rest through a sweep of poses (named_poses'
~move_to_joints), average the wrench at each, fit a bias map and write it (contact_control README, *Bias
map*). The wrench is taken as contact_control takes it: its sign flips, its configured tool subtracted."""

from __future__ import annotations

import argparse
import math
import sys
import threading
import time
from collections.abc import Sequence

import numpy as np
from contact_control.bias_map import BiasMapError, MapSample, fit_bias_map
from contact_control.frames import quaternion_matrix, rotation_angle
from contact_control.params import ParamError, load_settings
from contact_control.preprocess import WrenchPreprocessor

from control_stack.calibration import Box, CalibrationError, plan_sweep, read_poses

__all__ = ["main"]

REST_SPEED = 5e-3  # [rad/s] every joint slower than this ...
REST_TIME = 0.3  # [s] ... for this long: at rest
SAMPLE_TIME = 0.3  # [s] of wrenches averaged per pose
MAX_TURN = 0.01  # [rad] the sensor turning more while sampling: not at rest, sample again
MAX_SKIPPED = 0.2  # of the poses may fail to be reached before the sweep gives up


class _Inputs:
    """The latest joint state and the wrenches since `start_sampling`, from rospy's threads."""

    def __init__(self, joint_topic: str, wrench_topic: str) -> None:
        import rospy
        from geometry_msgs.msg import WrenchStamped
        from sensor_msgs.msg import JointState

        self._lock = threading.Lock()
        self.names: tuple[str, ...] = ()
        self.positions: list[float] = []
        self.speed = math.inf
        self.quiet_since = math.inf
        self._wrenches: list[tuple[float, ...]] | None = None
        self._q: list[list[float]] = []
        rospy.Subscriber(joint_topic, JointState, self._on_joints, queue_size=10)
        rospy.Subscriber(wrench_topic, WrenchStamped, self._on_wrench, queue_size=100)

    def _on_joints(self, msg) -> None:  # type: ignore[no-untyped-def]
        now = time.monotonic()
        with self._lock:
            self.names, self.positions = tuple(msg.name), list(msg.position)
            self.speed = max((abs(v) for v in msg.velocity), default=0.0)
            if self.speed > REST_SPEED:
                self.quiet_since = math.inf
            elif self.quiet_since == math.inf:
                self.quiet_since = now
            if self._wrenches is not None:
                self._q.append(list(msg.position))

    def _on_wrench(self, msg) -> None:  # type: ignore[no-untyped-def]
        f, t = msg.wrench.force, msg.wrench.torque
        with self._lock:
            if self._wrenches is not None:
                self._wrenches.append((f.x, f.y, f.z, t.x, t.y, t.z))

    def at_rest(self) -> bool:
        with self._lock:
            return time.monotonic() - self.quiet_since >= REST_TIME

    def start_sampling(self) -> None:
        with self._lock:
            self._wrenches, self._q = [], []

    def stop_sampling(self) -> tuple[list[tuple[float, ...]], list[list[float]]]:
        with self._lock:
            out = (self._wrenches or [], self._q)
            self._wrenches = None
            return out


def _sensor_rotation(buffer, fixed: str, frame: str) -> np.ndarray:  # type: ignore[no-untyped-def]
    import rospy
    from compliant_common.ros_tf_prefix import for_this_node

    prefix = for_this_node()  # the robot's frames on tf (README, Namespaces)
    q = buffer.lookup_transform(prefix.add(fixed), prefix.add(frame), rospy.Time(0),
                                rospy.Duration(1.0)).transform.rotation
    return np.array(quaternion_matrix(q.x, q.y, q.z, q.w))


def _run(args: argparse.Namespace) -> int:
    import rospy
    import tf2_ros
    from compliant_control_msgs.srv import MoveToJoints
    from jog_arm.jog_calcs import JogCalcs
    from jog_arm.settings import JogSettings

    rospy.init_node("calibrate_bias", anonymous=True)
    cc_ns, jog_ns = (rospy.resolve_name(n) + "/" for n in (args.contact_control, args.jog_arm))
    try:
        settings = load_settings(rospy.get_param(cc_ns, {}))
    except ParamError as err:
        print(f"calibrate_bias: contact_control's parameters ({cc_ns}): {err}", file=sys.stderr)
        return 2
    jog, _ = JogSettings.from_params_with_warnings(rospy.get_param(jog_ns, {}), jog_ns)
    arm = JogCalcs(jog, rospy.get_param("robot_description")).model
    tool = WrenchPreprocessor(load_settings({**rospy.get_param(cc_ns, {}), "bias_map": ""}))
    joint_topic = args.joint_states or rospy.resolve_name(jog.joint_topic, jog_ns)  # the arm's, as jog_arm's
    inputs = _Inputs(joint_topic, rospy.resolve_name(settings.ft_in_topic, cc_ns))
    tf = tf2_ros.Buffer()
    tf2_ros.TransformListener(tf)
    move_name = rospy.resolve_name(args.named_poses) + "/move_to_joints"
    rospy.wait_for_service(move_name, timeout=30)
    move = rospy.ServiceProxy(move_name, MoveToJoints)
    deadline = time.monotonic() + 10.0
    while not inputs.names and time.monotonic() < deadline:
        time.sleep(0.05)  # start-up: the first joint state
    if not inputs.names:
        print(f"calibrate_bias: no joint state on {joint_topic}", file=sys.stderr)
        return 1
    names, start = inputs.names, list(inputs.positions)
    model_q = [start[names.index(n)] for n in arm.joint_names]
    try:
        if args.poses:
            poses = read_poses(args.poses, arm.joint_names)
            where = f"from {args.poses}"
        else:
            poses = plan_sweep(arm, model_q, Box.parse(args.box), args.tilt, args.count)
            where = f"in the box {args.box} m around the arm's pose, tilted up to {args.tilt:g} rad"
    except CalibrationError as err:
        print(f"calibrate_bias: {err}", file=sys.stderr)
        return 2
    print(f"calibrate_bias: {len(poses)} poses {where}; the wrench of {settings.ft_in_topic} in "
          f"{settings.ft_sensor_frame}", flush=True)
    samples: list[MapSample] = []
    skipped = 0
    for k, q in enumerate(poses, start=1):
        answer = move(list(arm.joint_names), list(q), args.speed_scale, f"calibration pose {k}/{len(poses)}")
        if not answer.success:
            skipped += 1
            print(f"calibrate_bias: pose {k} skipped: {answer.message}", flush=True)
            if skipped > MAX_SKIPPED * len(poses):
                print("calibrate_bias: too many poses not reached: a smaller box or tilt", file=sys.stderr)
                return 1
            continue
        sample = _sample(inputs, tf, settings, tool, arm.joint_names)
        if sample is None:
            sample = _sample(inputs, tf, settings, tool, arm.joint_names)  # a jolt: once more
        if sample is None:
            skipped += 1
            print(f"calibrate_bias: pose {k}: not at rest while sampling, skipped", flush=True)
            continue
        samples.append(sample)
        f = ", ".join(f"{v:.2f}" for v in sample.wrench[:3])
        print(f"calibrate_bias: pose {k}/{len(poses)}: force at rest ({f}) N", flush=True)
    move(list(arm.joint_names), model_q, args.speed_scale, "the pose the calibration started from")
    command = "rosrun control_stack calibrate_bias " + " ".join(sys.argv[1:])
    try:
        fitted = fit_bias_map(arm.joint_names, samples, frame=settings.ft_sensor_frame, command=command)
    except BiasMapError as err:
        print(f"calibrate_bias: {err}", file=sys.stderr)
        return 1
    with open(args.output, "w") as out:
        out.write(fitted.to_yaml())
    print(f"calibrate_bias: {fitted.describe()}\ncalibrate_bias: wrote {args.output}; contact_control "
          f"subtracts it with its parameter bias_map (hardware.launch bias_map:={args.output})", flush=True)
    return 0


def _sample(inputs: _Inputs, tf, settings, tool: WrenchPreprocessor,  # type: ignore[no-untyped-def]
            joints: Sequence[str]) -> MapSample | None:
    """The mean wrench (sign flips, configured tool out) and joints at rest here; None if it moved."""
    deadline = time.monotonic() + 10.0
    while not inputs.at_rest() and time.monotonic() < deadline:
        time.sleep(0.02)
    r0 = _sensor_rotation(tf, settings.fixed_frame, settings.ft_sensor_frame)
    inputs.start_sampling()
    time.sleep(SAMPLE_TIME)  # collecting: the subscribers fill the buffers meanwhile
    wrenches, qs = inputs.stop_sampling()
    r1 = _sensor_rotation(tf, settings.fixed_frame, settings.ft_sensor_frame)
    if len(wrenches) < 5 or not qs or rotation_angle(r0.tolist(), r1.tolist()) > MAX_TURN:
        return None
    weight = tool.gravity_wrench(r1.tolist())
    net = np.mean([tool.oriented(w) for w in wrenches], axis=0) - np.array(weight)
    q_mean = np.mean(qs, axis=0)
    index = [inputs.names.index(n) for n in joints]
    u = r1.T @ np.asarray(settings.gravity, dtype=float)
    return MapSample(tuple(q_mean[index].tolist()), (float(u[0]), float(u[1]), float(u[2])),
                     tuple(net.tolist()))


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="calibrate_bias", description=__doc__)
    parser.add_argument("--output", required=True, help="the bias map file to write (YAML)")
    parser.add_argument("--box", default="-0.1,0.1,-0.1,0.1,-0.05,0.1",
                        help="tool tip offsets from the current pose, base axes [m]: "
                        "xlow,xhigh,ylow,yhigh,zlow,zhigh")
    parser.add_argument("--poses", default="", help="a YAML list of joint poses ({joint: position}) to use "
                        "instead of the box's sweep")
    parser.add_argument("--tilt", type=float, default=0.3, help="tool tilt about the base's X and Y [rad]")
    parser.add_argument("--count", type=int, default=60,
                        help="poses in the sweep (10 or more; 60 let a 6-joint arm fit a quadratic)")
    parser.add_argument("--speed-scale", type=float, default=0.5, help="named_poses' speed_scale")
    parser.add_argument("--contact-control", default="contact_control_node", help="its node name")
    parser.add_argument("--jog-arm", default="jog_arm_server", help="its node name (joints and tip)")
    parser.add_argument("--named-poses", default="named_poses", help="named_poses' node name")
    parser.add_argument("--joint-states", default="", help="sensor_msgs/JointState topic (default jog_arm's)")
    import rospy

    args = parser.parse_args(rospy.myargv(list(sys.argv[1:] if argv is None else argv)))
    return _run(args)
