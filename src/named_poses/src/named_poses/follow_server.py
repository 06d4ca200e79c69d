"""`~follow_joint_trajectory`: control_msgs/FollowJointTrajectory through named_poses' moves, so a MoveIt
configuration's controller can point at the stack (README, *FollowJointTrajectory*).

The goal is checked (`trajectory.Planned`; the collaborative speed cap at every 20 ms of it), sent to the
driver as one JointTrajectory the way a named-pose move is (jog_arm paused, the trajectory controller
switched on), and watched: the contact force (contact_control's `~contact_wrench`), the path tolerance, the
robot's own stop and a cancel each stop the arm where it is and end the goal with the reason.
"""

from __future__ import annotations

import math
import threading
import time
from typing import Any

import actionlib
import numpy as np
import rospy
from control_msgs.msg import (
    FollowJointTrajectoryAction,
    FollowJointTrajectoryFeedback,
    FollowJointTrajectoryGoal,
    FollowJointTrajectoryResult,
)
from geometry_msgs.msg import WrenchStamped
from jog_arm.body_regions import max_speed, region_named
from trajectory_msgs.msg import JointTrajectory, JointTrajectoryPoint

from named_poses.params import NamedPoseSettings
from named_poses.switching import SwitchError
from named_poses.trajectory import Planned, Tolerance, TrajectoryError

__all__ = ["FollowServer"]

R = FollowJointTrajectoryResult
CAP_STEP = 0.02  # [s] the speed cap is checked over this much of the trajectory at a time
WATCH_PERIOD = 0.005  # [s]


class FollowServer:
    """The action on the named-pose server `poses` (node.NamedPoseServer, not imported: it imports this;
    its joints, state, moves' lock and driver output)."""

    def __init__(self, poses: Any, settings: NamedPoseSettings, limits: dict) -> None:
        self.poses, self.s, self.limits = poses, settings, limits
        self._force = 0.0  # |F| of the last contact wrench while a trajectory runs [N]
        self._force_lock = threading.Lock()
        self._server = actionlib.SimpleActionServer("~follow_joint_trajectory", FollowJointTrajectoryAction,
                                                    execute_cb=self._execute, auto_start=False)
        self._server.start()

    def _on_wrench(self, msg: WrenchStamped) -> None:
        f = msg.wrench.force
        with self._force_lock:
            self._force = math.sqrt(f.x * f.x + f.y * f.y + f.z * f.z)

    def _execute(self, goal: FollowJointTrajectoryGoal) -> None:
        poses = self.poses
        if not poses._busy.acquire(blocking=False):
            self._end(R.INVALID_GOAL, "another named-pose move or trajectory is running")
            return
        sub = rospy.Subscriber(self.s.contact_wrench, WrenchStamped, self._on_wrench, queue_size=1,
                               tcp_nodelay=True)
        poses._moving = "a trajectory"
        try:
            code, why = self._run(goal)
        except TrajectoryError as err:
            code, why = err.code, str(err)
        finally:
            sub.unregister()
            poses._moving = ""
            poses._busy.release()
        poses._last_answer = f"trajectory: {why}"
        self._end(code, why)

    def _end(self, code: int, why: str) -> None:
        rospy.loginfo("named_pose_server: trajectory: %s", why)
        result = R(error_code=code, error_string=why)
        if code == R.SUCCESSFUL:
            self._server.set_succeeded(result, why)
        elif self._server.is_preempt_requested():
            self._server.set_preempted(result, why)
        else:
            self._server.set_aborted(result, why)

    def _plan(self, goal: FollowJointTrajectoryGoal, current: np.ndarray) -> Planned:
        """The goal checked against the arm, its limits and the collaborative speed cap."""
        poses, s, traj = self.poses, self.s, goal.trajectory
        points = [(p.time_from_start.to_sec(), list(p.positions), list(p.velocities)) for p in traj.points]
        plan = Planned.check(
            list(poses.poses.joints), self.limits, list(traj.joint_names), points,
            [Tolerance(t.name, t.position) for t in goal.path_tolerance],
            [Tolerance(t.name, t.position) for t in goal.goal_tolerance],
            goal.goal_time_tolerance.to_sec(), s.trajectory_path_tolerance or math.inf, poses.tolerance,
            s.trajectory_goal_time)
        jog = poses._jog
        region = rospy.get_param(f"{jog}/collaborative_region", "hand") if jog else "hand"
        payload = rospy.get_param(f"{jog}/collaborative_payload", 0.0) if jog else 0.0
        worst, at, mass = 0.0, 0.0, 0.0
        previous = current
        for t in np.arange(CAP_STEP, plan.duration + CAP_STEP, CAP_STEP):
            here = plan.desired(min(t, plan.duration), current)
            if np.any(here != previous):  # this step's ds/dt is 1 / CAP_STEP; the cap allows cap.speed
                cap = poses._path_cap.limit(region, payload, previous, here)
                ratio = 1.0 / (CAP_STEP * cap.speed)
                if ratio > worst:
                    worst, at, mass = ratio, float(t), cap.robot_mass
            previous = here
        if worst > 1.0 + 1e-6:
            tip = max_speed(region_named(region), mass)
            raise TrajectoryError(R.INVALID_GOAL, f"faster than the collaborative speed cap ({tip:.2f} m/s "
                                    f"at the tip toward the {region}, ISO/TS 15066) at {at:.2f} s: plan it "
                                    f"{worst:.2f} times slower (MoveIt: the velocity scaling factor)")
        return plan

    def _run(self, goal: FollowJointTrajectoryGoal) -> tuple[int, str]:
        with self.poses.listening():
            return self._run_listening(goal)

    def _run_listening(self, goal: FollowJointTrajectoryGoal) -> tuple[int, str]:
        poses = self.poses
        why, current = poses.ready()  # the same refusals as a named-pose move's
        if current is None:
            return R.INVALID_GOAL, f"refused: {why}"
        plan = self._plan(goal, current)
        stamp = goal.trajectory.header.stamp
        start = stamp.to_sec() if not stamp.is_zero() else rospy.get_time()
        if start + plan.duration < rospy.get_time():
            return R.OLD_HEADER_TIMESTAMP, (f"refused: the trajectory stamped {start:.3f} ended "
                                            f"{rospy.get_time() - start - plan.duration:.2f} s ago")
        try:
            paused = poses._pause_jog()
        except SwitchError as exc:
            return R.INVALID_GOAL, f"refused: {exc}"
        try:
            switch = poses._switch_on()
        except SwitchError as exc:
            return R.INVALID_GOAL, f"refused: {exc}{poses._resume_jog(paused)}"
        try:
            silent = poses.trajectory_listener()
            code, why = ((R.INVALID_GOAL, f"refused: {silent}") if silent else
                         self._follow(plan, current, start, goal.trajectory.header.stamp))
        finally:
            if switch is not None:
                poses._switch(switch.undo())
            why_resumed = poses._resume_jog(paused)
        return code, why + why_resumed

    def _send(self, plan: Planned, stamp: rospy.Time) -> None:
        msg = JointTrajectory()
        msg.header.stamp = stamp
        msg.joint_names = list(self.poses.poses.joints)
        for i, t in enumerate(plan.times):
            v = plan.velocities[i].tolist() if plan.velocities is not None else []
            msg.points.append(JointTrajectoryPoint(positions=plan.positions[i].tolist(), velocities=v,
                                                   time_from_start=rospy.Duration.from_sec(float(t))))
        self.poses._pub.publish(msg)

    def _hold(self, at: np.ndarray) -> None:
        """The arm stops where it is: a trajectory of one point there, now."""
        msg = JointTrajectory()
        msg.joint_names = list(self.poses.poses.joints)
        msg.points.append(JointTrajectoryPoint(positions=at.tolist(), velocities=[0.0] * len(at),
                                               time_from_start=rospy.Duration.from_sec(0.0)))
        self.poses._pub.publish(msg)

    def _follow(self, plan: Planned, start_q: np.ndarray, start: float, stamp: rospy.Time) -> tuple[int, str]:
        """Sends the trajectory and watches it to its end (README, FollowJointTrajectory)."""
        poses, s, joints = self.poses, self.s, list(self.poses.poses.joints)
        with self._force_lock:
            self._force = 0.0
        self._send(plan, stamp)
        feedback = FollowJointTrajectoryFeedback(joint_names=joints)
        next_feedback, period = 0.0, 1.0 / s.trajectory_feedback_rate
        deadline = start + plan.duration + plan.goal_time
        while not rospy.is_shutdown():
            now = rospy.get_time()
            t = now - start
            actual = poses._current()
            if actual is None:
                time.sleep(WATCH_PERIOD)
                continue
            desired = plan.desired(max(t, 0.0), start_q)
            with self._force_lock:
                force = self._force
            stop = ""
            code = R.PATH_TOLERANCE_VIOLATED
            if self._server.is_preempt_requested():
                stop = f"cancelled at {max(t, 0.0):.2f} s of {plan.duration:.2f} s"
            elif poses._robot_stop:
                stop = f"stopped at {t:.2f} s: {poses._robot_stop}"
            elif force >= s.trajectory_force_limit:
                stop = (f"stopped at the contact force limit: {force:.1f} N reached trajectory_force_limit "
                        f"{s.trajectory_force_limit:g} N at {t:.2f} s of {plan.duration:.2f} s")
            elif t <= plan.duration and (k := plan.off_path(actual, desired)) >= 0:
                stop = (f"stopped at {t:.2f} s: {joints[k]} {abs(actual[k] - desired[k]):.4f} off its path "
                        f"(path tolerance {plan.path_tolerance[k]:g})")
            if stop:
                self._hold(actual)
                return code, stop
            if now >= next_feedback:
                next_feedback = now + period
                feedback.header.stamp = rospy.Time.from_sec(now)
                feedback.desired.positions, feedback.actual.positions = desired.tolist(), actual.tolist()
                feedback.error.positions = (desired - actual).tolist()
                feedback.desired.time_from_start = feedback.actual.time_from_start = rospy.Duration.from_sec(
                    max(t, 0.0))
                self._server.publish_feedback(feedback)
            if t >= plan.duration:
                off = plan.off_goal(actual)
                if not off:
                    return R.SUCCESSFUL, f"done: {len(plan.times)} points in {plan.duration:.2f} s"
                if now >= deadline:
                    worst = max(off, key=lambda k: abs(actual[k] - plan.positions[-1][k]))
                    return R.GOAL_TOLERANCE_VIOLATED, (
                        f"{joints[worst]} {abs(actual[worst] - plan.positions[-1][worst]):.4f} from its goal "
                        f"{plan.goal_time:g} s after the end (goal tolerance {plan.goal_tolerance[worst]:g})")
            time.sleep(WATCH_PERIOD)
        return R.PATH_TOLERANCE_VIOLATED, "shutting down"
