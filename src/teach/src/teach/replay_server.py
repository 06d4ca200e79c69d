"""program_server's `~replay` action: a program played back with compliance (see the package README).

A joint move to the program's first pose (named_poses' `~move_to_joints`), then contact_control's path law on
every axis along the recorded path (the reference streamed on `~path_reference` at `replay_rate`), or, with
`press_axis`, force tracking on that axis (the path starts once it touches). Feedback: state, progress, the
tool's distance from the recorded path, the contact force. Ends with the path done, a cancel, or the reason
contact_control ended the move (a force limit with its exceeded action, a lost path).
"""

from __future__ import annotations

import math
import threading
from collections.abc import Callable

import actionlib
import numpy as np
import rospy
import tf2_ros
from compliant_common.errors import StackError
from compliant_common.ros_tf_prefix import for_this_node
from compliant_control_msgs.msg import (
    AxisLaw,
    ContactControlStatus,
    ContactEvent,
    PathReference,
    ReplayProgramAction,
    ReplayProgramFeedback,
    ReplayProgramGoal,
    ReplayProgramResult,
)
from compliant_control_msgs.srv import ConfigureLaws, ConfigureLawsRequest, MoveToJoints
from contact_control.params import ParamError, load_settings
from geometry_msgs.msg import Pose
from sensor_msgs.msg import JointState
from std_srvs.srv import Trigger, TriggerRequest, TriggerResponse

from teach.params import TeachSettings
from teach.playback import Playback, path_distance
from teach.program import Program, ProgramError, ProgramStore
from teach.simplify import quaternion_angle
from teach.timing import Limits

__all__ = ["ReplayServer"]


def _slowed(error: float, limit: float) -> float:
    """1 up to `limit`, then falling linearly to 0.1 at twice it."""
    return 1.0 if error <= limit else max(0.1, 1.0 - 0.9 * (error - limit) / limit)

AXES = ("x", "y", "z", "rx", "ry", "rz")
PRESS_AXES = ("x", "y", "z")
FEEDBACK_EVERY = 10  # reference cycles per feedback message (10 Hz at 100 Hz)
_TF_ERRORS = (tf2_ros.LookupException, tf2_ros.ConnectivityException, tf2_ros.ExtrapolationException)


class _Late:
    """The worst lateness of one replay, said with its result: a path error on a loaded machine then shows
    whether this node's loop stalled or the tool's pose it judged by was old."""

    def __init__(self) -> None:
        self.gap = self.age = 0.0  # [s] the longest time between two cycles; the oldest tool pose used
        self.farthest, self.at = -1.0, math.nan  # [m] the tool's largest distance off the path; its progress

    def said(self, period: float) -> str:
        parts = []
        if self.gap > 2.5 * period:
            parts.append(f"this node's loop ran late (up to {self.gap:.2f} s between cycles)")
        if self.age > 0.05:
            parts.append(f"the tool's pose was up to {self.age:.2f} s old")
        return "; " + " and ".join(parts) if parts else ""


class ReplayError(StackError):
    """The replay cannot start or go on; the message is the action's result message."""


class ReplayServer:
    """`~replay` (actionlib), `~pause`, `~resume`; one replay at a time."""

    def __init__(self, s: TeachSettings, store: ProgramStore, robot: str, base_frame: str, tip_frame: str,
                 tf: tf2_ros.Buffer, listen_tf: Callable[[], None], recording: Callable[[], bool]) -> None:
        self.s, self.store, self.robot = s, store, robot
        self.base_frame, self.tip_frame = base_frame, tip_frame
        self._tf = tf
        self._listen_tf = listen_tf
        self._recording = recording
        cc = rospy.resolve_name(s.contact_control_node)
        self._cc = cc
        self._ref_pub = rospy.Publisher(cc + "/path_reference", PathReference, queue_size=1, tcp_nodelay=True)
        self._configure = rospy.ServiceProxy(rospy.resolve_name("configure_laws"), ConfigureLaws)
        self._stop = rospy.ServiceProxy(cc + "/stop", Trigger)
        poses = rospy.resolve_name(s.named_poses_node)
        self._move = rospy.ServiceProxy(poses + "/move_to_joints", MoveToJoints)
        self._status: ContactControlStatus | None = None
        self._events: list[ContactEvent] = []
        self._lock = threading.Lock()
        self._playback: Playback | None = None
        self._lead = s.replay_lead  # [s] this replay's (`_arm`)
        self._late = _Late()
        self._ref = PathReference(horizon_step=s.replay_horizon_step)
        self._prefix = for_this_node()  # the robot's frames on tf and in messages; programs keep bare names
        self._ref.header.frame_id = self._prefix.add(base_frame)
        self._ref.horizon = [Pose() for _ in range(round(s.replay_horizon / s.replay_horizon_step))]
        self._server = actionlib.SimpleActionServer("~replay", ReplayProgramAction, self._execute,
                                                    auto_start=False)
        self._services = [rospy.Service("~pause", Trigger, self._on_pause),
                          rospy.Service("~resume", Trigger, self._on_resume)]
        self._server.start()

    def describe(self) -> str:
        """The replay running, in words ('' when none)."""
        with self._lock:
            play = self._playback
        if play is None:
            return ""
        state = "paused" if play.paused else "replaying"
        return f"{state} '{play.program.name}' at {play.speed:.3g} x, {play.progress:.0%}"

    # --- pause / resume ---
    def _on_pause(self, _req: TriggerRequest) -> TriggerResponse:
        with self._lock:
            play = self._playback
            if play is None:
                return TriggerResponse(success=False, message="no replay is running")
            play.paused = True
        return TriggerResponse(success=True, message=f"paused at {play.progress:.0%} (the tool holds still)")

    def _on_resume(self, _req: TriggerRequest) -> TriggerResponse:
        with self._lock:
            play = self._playback
            if play is None or not play.paused:
                return TriggerResponse(success=False, message="no paused replay")
            play.paused = False
        return TriggerResponse(success=True, message=f"resumed at {play.progress:.0%}")

    # --- the action ---
    def _execute(self, goal: ReplayProgramGoal) -> None:
        subs = [rospy.Subscriber(self._cc + "/status", ContactControlStatus, self._on_status, queue_size=1),
                rospy.Subscriber(self._cc + "/events", ContactEvent, self._on_event, queue_size=50)]
        self._status, self._events = None, []
        try:
            result = self._replay(goal)
        except ReplayError as err:
            result = ReplayProgramResult(success=False, message=str(err))
        finally:
            for sub in subs:
                sub.unregister()
            with self._lock:
                self._playback = None
        result.contacts = list(self._events)
        rospy.loginfo("teach: replay '%s': %s", goal.name, result.message)
        if result.success:
            self._server.set_succeeded(result, result.message)
        elif self._server.is_preempt_requested():
            self._server.set_preempted(result, result.message)
        else:
            self._server.set_aborted(result, result.message)

    def _on_status(self, msg: ContactControlStatus) -> None:
        self._status = msg

    def _on_event(self, msg: ContactEvent) -> None:
        self._events.append(msg)

    def _check(self, goal: ReplayProgramGoal) -> tuple[Program, float, int]:
        """The program, the speed and the press axis's index (-1: none), or a ReplayError saying why not."""
        s = self.s
        if self._recording():
            raise ReplayError("refused: a recording runs (stop it first: teach stop)")
        try:
            program = self.store.load(goal.name)
            joints = rospy.wait_for_message(rospy.resolve_name(s.joint_states_topic), JointState, timeout=2.0)
            program.check_robot(self.robot, joints.name)
        except ProgramError as err:
            raise ReplayError(f"refused: {err}") from None
        except rospy.ROSException:
            topic = rospy.resolve_name(s.joint_states_topic)
            raise ReplayError(f"refused: no joint state on {topic}") from None
        if (program.base_frame, program.tip_frame) != (self.base_frame, self.tip_frame):
            raise ReplayError(f"refused: program '{program.name}' is the pose of {program.tip_frame} in "
                              f"{program.base_frame}; contact_control controls {self.tip_frame} in "
                              f"{self.base_frame}")
        speed = goal.speed or 1.0
        if not 0.0 < speed <= s.replay_max_speed:
            raise ReplayError(f"refused: speed {goal.speed} must be in (0, {s.replay_max_speed:g}] (0: 1)")
        press = -1
        if goal.press_axis:
            if goal.press_axis not in PRESS_AXES:
                raise ReplayError(f"refused: press_axis {goal.press_axis!r} must be one of x, y, z or empty")
            if not 0.0 < abs(goal.press_force) < s.replay_force_limit:
                raise ReplayError(f"refused: press_force {goal.press_force:g} N must be non-zero and below "
                                  f"replay_force_limit {s.replay_force_limit:g} N")
            press = PRESS_AXES.index(goal.press_axis)
        status = self._wait_status()
        if status.guiding:
            raise ReplayError("refused: hand-guiding is on (teach guide off)")
        if status.move_active:
            raise ReplayError(f"refused: a contact move is running ({status.message or 'stop it first'})")
        return program, speed, press

    def _wait_status(self) -> ContactControlStatus:
        deadline = rospy.get_time() + 2.0
        while self._status is None and rospy.get_time() < deadline and not rospy.is_shutdown():
            rospy.sleep(0.02)
        if self._status is None:
            raise ReplayError(f"refused: no status from contact_control on {self._cc}/status")
        return self._status

    def _laws(self, press: int, force: float, turns: bool) -> ConfigureLawsRequest:
        """Path law on every axis, force tracking on the press axis; pressing, a program that does not turn
        the tool (`turns` False) leaves its orientation to the arm (law none, as surface following does):
        held through the path law's orientation loop, the friction of the sliding tool made a simulated UR3
        stick-slip (normal force std 2 N instead of 0.06 N, teach's README)."""
        s = self.s
        req = ConfigureLawsRequest()
        for i, name in enumerate(AXES):
            angular = i >= 3
            limit = s.replay_torque_limit if angular else s.replay_force_limit
            action = s.replay_exceeded_action if limit > 0.0 else 0  # nothing to exceed
            if angular and press >= 0 and not turns:
                law = AxisLaw(law=AxisLaw.NONE)
            elif i == press:
                law = AxisLaw(law=AxisLaw.FORCE_TRACKING, damping=s.replay_press_damping, target_force=force,
                              velocity=s.replay_press_approach,
                              force_limit=limit, exceeded_action=action)
            else:
                law = AxisLaw(law=AxisLaw.PATH, stiffness=s.replay_gain,
                              damping=s.replay_damping_angular if angular else s.replay_damping_linear,
                              max_travel=s.replay_max_angle_error if angular else s.replay_max_path_error,
                              force_limit=limit, exceeded_action=action)
            setattr(req, name, law)
        return req

    def _tool(self) -> np.ndarray | None:
        try:
            prefix = self._prefix
            tf = self._tf.lookup_transform(prefix.add(self.base_frame), prefix.add(self.tip_frame),
                                           rospy.Time(0))
        except _TF_ERRORS:
            return None
        stamp = tf.header.stamp.to_sec()
        if stamp > 0.0:
            self._late.age = max(self._late.age, rospy.get_time() - stamp)
        p = tf.transform.translation
        return np.array([p.x, p.y, p.z])

    def _send(self, play: Playback) -> None:
        p, q, v = play.reference(self._lead)
        ref = self._ref
        ref.header.stamp = rospy.Time.now()
        pos, ori = ref.pose.position, ref.pose.orientation
        pos.x, pos.y, pos.z = (float(x) for x in p)
        ori.x, ori.y, ori.z, ori.w = q
        lin, ang = ref.velocity.linear, ref.velocity.angular
        lin.x, lin.y, lin.z, ang.x, ang.y, ang.z = (float(x) for x in v)
        for pose, (p, q) in zip(ref.horizon, play.horizon(ref.horizon_step, len(ref.horizon)), strict=True):
            pose.position.x, pose.position.y, pose.position.z = (float(x) for x in p)
            pose.orientation.x, pose.orientation.y, pose.orientation.z, pose.orientation.w = q
        self._ref_pub.publish(ref)

    def _replay(self, goal: ReplayProgramGoal) -> ReplayProgramResult:
        s = self.s
        program, speed, press = self._check(goal)
        self._listen_tf()
        feedback = ReplayProgramFeedback(state="moving to the start")
        self._server.publish_feedback(feedback)
        first = program.waypoints[0]
        try:
            moved = self._move(joint_names=list(program.joint_names), positions=list(first.joints),
                               speed_scale=s.start_speed_scale,
                               label=f"the start of program '{program.name}'")
        except (rospy.ServiceException, rospy.ROSException) as err:
            raise ReplayError(f"could not move to the start: {err}") from None
        if not moved.success:
            raise ReplayError(f"could not move to the start: {moved.message}")
        smoothing = s.replay_press_smoothing if press >= 0 else s.replay_smoothing
        limits, self._lead = self._arm()
        play = Playback(program, speed, limits, smoothing)
        with self._lock:
            self._playback = play
        rate = rospy.Rate(s.replay_rate)
        for _ in range(3):  # the reference is there before the laws (the path law ends without one)
            self._send(play)
            rate.sleep()
        start_q = first.orientation
        turns = any(quaternion_angle(start_q, w.orientation) > s.angle_tolerance for w in program.waypoints)
        answer = self._configure(self._laws(press, goal.press_force, turns))
        if not answer.success:
            raise ReplayError(f"contact_control refused the replay's laws: {answer.message}")
        move_started = rospy.get_time()
        path = np.array([w.position for w in program.waypoints])
        keep = [i for i in range(3) if i != press]
        distances: list[float] = []
        forces: list[float] = []
        state = "pressing" if press >= 0 else "replaying"
        last, cycle, settle_until = rospy.get_time(), 0, None
        steady_since: float | None = None
        tool: np.ndarray | None = None
        replay_started = rospy.get_time()
        active_seen = False
        target = goal.press_force
        ours = True  # the move is still ours to stop (contact_control did not end it)
        self._late = _Late()
        try:
            while not rospy.is_shutdown():
                now = rospy.get_time()
                if state == "replaying":
                    self._late.gap = max(self._late.gap, now - last)
                # A stall moves the program's clock on as far as the horizon that contact_control followed
                # meanwhile, a clock jump no further; never backwards.
                dt, last = min(max(now - last, 0.0), max(2.0 / s.replay_rate, s.replay_horizon)), now
                if self._server.is_preempt_requested():
                    return self._ended(False, f"cancelled at {play.progress:.0%}", distances, forces)
                status = self._status
                if status is not None and status.move_active:
                    active_seen = True  # a status from before the laws were set would say "no move"
                elif not active_seen and now - move_started > 2.0:
                    return self._ended(False, "contact_control's status never showed the replay's move",
                                       distances, forces)
                if active_seen and status is not None and not status.move_active:
                    why = status.message or "contact_control ended the move"
                    ours = False  # its exceeded action (moving away) goes on
                    return self._ended(False, f"stopped at {play.progress:.0%}: {why}", distances, forces)
                force = 0.0
                if status is not None:
                    f = status.wrench.force
                    force = (f.x, f.y, f.z)[press] if press >= 0 else math.sqrt(f.x**2 + f.y**2 + f.z**2)
                if state == "pressing":
                    if abs(force - target) > s.press_tolerance * abs(target):
                        steady_since = None
                    elif steady_since is None:
                        steady_since = now
                    if steady_since is not None and now - steady_since >= s.press_settle_time:
                        state, last = "replaying", rospy.get_time()
                        replay_started = last
                    elif now - move_started > s.press_timeout:
                        return self._ended(False, f"no steady contact force along {goal.press_axis} within "
                                                  f"{s.press_timeout:g} s", distances, forces)
                else:
                    play.advance(dt, self._keep_up(play, tool, keep))
                    if press >= 0:
                        forces.append(force)
                tool = self._tool()
                distance = math.nan
                if tool is not None and state == "replaying":
                    distance = float(path_distance(tool[None, keep], path[:, keep])[0])
                    if distance > self._late.farthest:
                        self._late.farthest, self._late.at = distance, play.progress
                    distances.append(distance)
                self._send(play)
                cycle += 1
                if cycle % FEEDBACK_EVERY == 0:
                    feedback.state = "paused" if play.paused else state
                    feedback.progress, feedback.path_error, feedback.force = play.progress, distance, force
                    self._server.publish_feedback(feedback)
                if play.done:
                    settle_until = settle_until or now + s.settle_time
                    if now >= settle_until:
                        done = f"program '{program.name}' replayed at {speed:.3g} x its speed"
                        took, asked = now - replay_started - s.settle_time, play.duration / speed
                        if play.planned > 1.05 * asked:
                            done += (f", slowed to the arm's limits where it was faster "
                                     f"({play.planned:.1f} s planned instead of {asked:.1f} s)")
                        if took > 1.1 * play.planned + 0.2:
                            done += f", and where the arm could not keep up ({took:.1f} s)"
                        return self._ended(True, done,
                                           distances, forces)
                rate.sleep()
            return self._ended(False, "shutting down", distances, forces)
        finally:
            if ours:
                self._stop_move()

    def _arm(self) -> tuple[Limits, float]:
        """contact_control's velocity and acceleration limits (its parameters read as it reads them) times
        `replay_limit_fraction`: what the replay's timing is planned against; and the fed-forward twist's
        lead [s]: `replay_lead`, or contact_control's `command_latency` when that is longer (an arm
        commanded through a slower path turns a corner that much later).

        Raises:
            ReplayError: contact_control's parameters are not valid (it would not have started with them).
        """
        try:
            settings = load_settings(rospy.get_param(self._cc, {}))
        except ParamError as err:
            raise ReplayError(f"refused: contact_control's parameters: {err}") from None
        lin, ang = settings.tuning(False), settings.tuning(True)
        # Slowing down is planned as gently as speeding up: contact_control's deceleration limit (2.5 m/s^2 by
        # default) is more than a simulated UR3 followed (12 mm past the L's corner at 2 x).
        limits = Limits(lin.max_velocity, lin.acceleration, min(lin.deceleration, lin.acceleration),
                        ang.max_velocity, ang.acceleration, min(ang.deceleration, ang.acceleration),
                        ).scaled(self.s.replay_limit_fraction)
        return limits, max(self.s.replay_lead, settings.command_latency)

    def _keep_up(self, play: Playback, tool: np.ndarray | None, keep: list[int]) -> float:
        """How fast the program's clock runs now (1: the requested speed). It slows while the tool is more
        than `replay_lag` off the reference across the path's direction (a corner being cut) or more than
        `replay_lag_along` behind it (the arm at its limits), down to a tenth at twice either, so the
        reference waits for the arm instead of running away from it."""
        if tool is None:
            return 1.0
        reference, _, twist = play.reference()
        error = reference[keep] - tool[keep]
        velocity = twist[:3][keep]
        speed = float(np.linalg.norm(velocity))
        across = error if speed < 1e-6 else error - (error @ velocity) / speed**2 * velocity
        s = self.s
        return min(_slowed(float(np.linalg.norm(across)), s.replay_lag),
                   _slowed(float(np.linalg.norm(error)), s.replay_lag_along))

    def _stop_move(self) -> None:
        try:
            self._stop()
        except (rospy.ServiceException, rospy.ROSException) as err:
            rospy.logwarn("teach: could not stop contact_control's move: %s", err)

    def _ended(self, ok: bool, message: str, distances: list[float],
               forces: list[float]) -> ReplayProgramResult:
        result = ReplayProgramResult(success=ok, message=message)
        if distances:
            d = np.array(distances)
            result.path_error_rms, result.path_error_max = float(np.sqrt(np.mean(d**2))), float(np.max(d))
            result.message += f"; path error {result.path_error_rms * 1e3:.2f} mm RMS, " \
                              f"{result.path_error_max * 1e3:.2f} mm max (at {self._late.at:.0%})"
        if forces:
            f = np.array(forces)
            result.force_mean, result.force_min, result.force_max = (float(f.mean()), float(f.min()),
                                                                     float(f.max()))
            result.message += (f"; force {result.force_mean:.2f} N ({result.force_min:.2f} to "
                               f"{result.force_max:.2f})")
        result.message += self._late.said(1.0 / self.s.replay_rate)
        return result
