"""task_server: the `~execute` action (compliant_control_msgs/ExecuteTask) over `run.TaskRun` (the README).

A thin adapter: tf gives the tool's pose, contact_control's `~status` the wrench and whether the step's move
runs, its `~events` the touches; the run's commands become ConfigureLaws calls, `~path_reference` messages
and `~stop` calls. One task at a time; cancel stops the arm. Inputs only while a task runs: idle, the node
costs the stack nothing.
"""

from __future__ import annotations

import math
import os
import sys
import threading
import time
from collections.abc import Callable, Sequence

import actionlib
import numpy as np
import rospkg
import rospy
import tf2_ros
from compliant_common.diagnostics import OK, Report
from compliant_common.ros_diagnostics import DiagnosticsPublisher
from compliant_common.ros_tf_prefix import for_this_node
from compliant_common.typedefs import FloatArray
from compliant_control_msgs.msg import (
    ContactControlStatus,
    ContactEvent,
    ExecuteTaskAction,
    ExecuteTaskFeedback,
    ExecuteTaskGoal,
    ExecuteTaskResult,
    PathReference,
)
from compliant_control_msgs.srv import ConfigureLaws, ConfigureLawsRequest
from contact_control.frames import matrix_quaternion, quaternion_matrix
from dynamic_reconfigure.client import Client
from geometry_msgs.msg import Point, Pose, Quaternion, TransformStamped
from std_msgs.msg import String
from std_srvs.srv import Trigger

from contact_tasks.params import TaskServerSettings, load_settings
from contact_tasks.path_server import FollowPathServer
from contact_tasks.run import FAILED, RUNNING, SUCCEEDED, Command, Observation, TaskRun
from contact_tasks.task import AXIS_NAMES, Task, TaskError
from contact_tasks.task_file import load_task, load_task_file

__all__ = ["TaskServer", "main"]

_TF_ERRORS = (tf2_ros.LookupException, tf2_ros.ConnectivityException, tf2_ros.ExtrapolationException)
# [s] a step's frame (law_frame tool_at_start) reaches this node's tf, then contact_control's, within this
_FRAME_WAIT = 2.0
_LAW_FIELDS = ("law", "damping", "stiffness", "velocity", "force_limit", "max_travel", "exceeded_action",
               "target_force")


class TaskServer:
    """`~execute`; see the module docstring."""

    def __init__(self, s: TaskServerSettings, fixed_frame: str, eef_frame: str, tasks_dir: str) -> None:
        self.s, self.fixed_frame, self.eef_frame, self.tasks_dir = s, fixed_frame, eef_frame, tasks_dir
        cc = rospy.resolve_name(s.contact_control_node)
        self.cc = cc
        self._ref_pub = rospy.Publisher(cc + "/path_reference", PathReference, queue_size=1, tcp_nodelay=True)
        self._configure = rospy.ServiceProxy(rospy.resolve_name("configure_laws"), ConfigureLaws)
        self._stop = rospy.ServiceProxy(cc + "/stop", Trigger)
        self.tf = tf2_ros.Buffer()
        self.tf_prefix = for_this_node()  # the robot's frames on tf and in messages (README, Namespaces)
        self._listener: tf2_ros.TransformListener | None = None
        self._broadcaster: tf2_ros.StaticTransformBroadcaster | None = None  # the step frame's, once needed
        self.step_frame = rospy.get_name().rsplit("/", 1)[-1] + "_step_start"
        self._lock = threading.Lock()
        self._status: ContactControlStatus | None = None
        self._touched = self._released = False
        self._robot_stop = ""  # jog_arm's ~robot_stop while a task runs
        self._not_before = math.inf  # events from before the task are ignored
        self._laws_at = math.inf
        self._subs: list[rospy.Subscriber] = []
        self._run: TaskRun | None = None  # the task running, for /diagnostics
        self._last = "idle"
        #: Held while a task or a path runs: one at a time.
        self.busy = threading.Lock()
        self._server = actionlib.SimpleActionServer("~execute", ExecuteTaskAction, self._execute,
                                                    auto_start=False)
        self._server.start()
        self._paths = FollowPathServer(self)
        self._health = DiagnosticsPublisher(self._health_report)

    def _health_report(self) -> Report:
        """/diagnostics: the running task and step, or the last task's outcome. Every fault here is a goal's
        answer, so the level stays OK."""
        report = Report(rospy.get_name())
        with self._lock:
            run = self._run
            report.check(OK, f"task '{run.task.name}', step '{run.step_name}'" if run else self._last)
        report.value("tasks_dir", self.tasks_dir)
        return report

    # inputs

    def _listen(self) -> None:
        if self._listener is None:
            self._listener = tf2_ros.TransformListener(self.tf)
        self._subs = [
            rospy.Subscriber(self.cc + "/status", ContactControlStatus, self._on_status, queue_size=1),
            rospy.Subscriber(self.cc + "/events", ContactEvent, self._on_event, queue_size=50),
            rospy.Subscriber(self.s.jog_arm + "/robot_stop", String, self._on_robot_stop, queue_size=5),
        ]

    def _unlisten(self) -> None:
        for sub in self._subs:
            sub.unregister()
        self._subs = []
        with self._lock:
            self._status, self._robot_stop = None, ""

    def _wait_for_inputs(self) -> tuple[ContactControlStatus | None, FloatArray | None]:
        """The first status and tool pose, waiting up to `status_timeout` (the time's own clock)."""
        deadline = rospy.get_time() + self.s.status_timeout
        poll = rospy.Rate(50.0)
        while not rospy.is_shutdown():
            with self._lock:
                status = self._status
            tool = self._tool()
            if (status is not None and tool is not None) or rospy.get_time() >= deadline:
                return status, tool
            poll.sleep()
        return None, None

    def _on_status(self, msg: ContactControlStatus) -> None:
        with self._lock:
            self._status = msg

    def _on_robot_stop(self, msg: String) -> None:
        with self._lock:
            self._robot_stop = msg.data

    def _on_event(self, msg: ContactEvent) -> None:
        with self._lock:
            if msg.header.stamp.to_sec() >= self._not_before:
                self._touched |= msg.type == ContactEvent.TOUCH
                self._released |= msg.type == ContactEvent.RELEASE

    def _tool(self) -> FloatArray | None:
        try:
            prefix = self.tf_prefix
            tf = self.tf.lookup_transform(prefix.add(self.fixed_frame), prefix.add(self.eef_frame),
                                          rospy.Time(0))
        except _TF_ERRORS:
            return None
        p, q = tf.transform.translation, tf.transform.rotation
        pose = np.eye(4)
        pose[:3, :3] = quaternion_matrix(q.x, q.y, q.z, q.w)
        pose[:3, 3] = (p.x, p.y, p.z)
        return pose

    def _observe(self, tool: FloatArray) -> Observation:
        with self._lock:
            status, robot_stop = self._status, self._robot_stop
            touched, released = self._touched, self._released
            self._touched = self._released = False
        wrench: tuple[float, ...] = (0.0,) * 6
        active, message = True, ""
        if status is not None:
            f, t = status.wrench.force, status.wrench.torque
            wrench = (f.x, f.y, f.z, t.x, t.y, t.z)
            if status.header.stamp.to_sec() >= self._laws_at:  # it knows the step's laws
                active, message = status.move_active, status.message
        return Observation(rospy.get_time(), tool, wrench, active, message, touched, released, robot_stop)

    # outputs

    def _apply(self, run: TaskRun, command: Command, obs: Observation) -> Command:
        ref = command.reference
        if ref is not None:
            msg = PathReference()
            msg.header.stamp, msg.header.frame_id = rospy.Time.now(), self.tf_prefix.add(self.fixed_frame)
            p, q, v = msg.pose.position, msg.pose.orientation, msg.velocity
            p.x, p.y, p.z = ref.position
            q.x, q.y, q.z, q.w = ref.quaternion
            v.linear.x, v.linear.y, v.linear.z, v.angular.x, v.angular.y, v.angular.z = ref.twist
            msg.horizon_step = ref.horizon_step
            msg.horizon = [Pose(position=Point(*position), orientation=Quaternion(*quaternion))
                           for position, quaternion in ref.horizon]
            self._ref_pub.publish(msg)
        if command.laws is not None:
            if command.restart:
                self._call_stop()
            req = ConfigureLawsRequest(frame=getattr(command.laws, "frame", ""))
            for axis in AXIS_NAMES:
                given, law = getattr(command.laws, axis), getattr(req, axis)
                for name in _LAW_FIELDS:
                    setattr(law, name, getattr(given, name))
            pose = command.frame_pose
            why = self._put_step_frame(pose) if pose is not None else ""
            ok = not why
            if ok:
                ok, why = self._send_laws(req, frame_put=pose is not None)
            self._laws_at = rospy.get_time()
            if not ok:
                return self._apply(run, run.refused(why, obs), obs)
        if command.stop:
            self._call_stop()
        return command

    def _send_laws(self, req: ConfigureLawsRequest, frame_put: bool) -> tuple[bool, str]:
        """ConfigureLaws: (accepted, contact_control's message). A step frame just put on tf may reach
        contact_control a moment after this node: its "not available" is asked again until _FRAME_WAIT."""
        deadline = time.monotonic() + _FRAME_WAIT
        while True:
            try:
                answer = self._configure(req)
            except (rospy.ServiceException, rospy.ROSException) as err:
                return False, f"configure_laws failed: {err}"
            if answer.success or not frame_put or "is not available" not in answer.message \
                    or time.monotonic() > deadline:
                return answer.success, answer.message
            time.sleep(0.01)

    def _put_step_frame(self, pose: FloatArray) -> str:
        """`step_frame` on tf (static) at the tool's `pose` in the fixed frame; "" once this node's own tf
        has it, else why not."""
        if self._broadcaster is None:
            self._broadcaster = tf2_ros.StaticTransformBroadcaster()
        parent, child = self.tf_prefix.add(self.fixed_frame), self.tf_prefix.add(self.step_frame)
        msg = TransformStamped()
        msg.header.stamp, msg.header.frame_id, msg.child_frame_id = rospy.Time.now(), parent, child
        t, q = msg.transform.translation, msg.transform.rotation
        t.x, t.y, t.z = (float(v) for v in pose[:3, 3])
        q.x, q.y, q.z, q.w = matrix_quaternion(pose[:3, :3].tolist())
        self._broadcaster.sendTransform(msg)
        deadline = time.monotonic() + _FRAME_WAIT
        while time.monotonic() < deadline and not rospy.is_shutdown():
            try:
                got = self.tf.lookup_transform(parent, child, rospy.Time(0)).transform.translation
                if abs(got.x - t.x) + abs(got.y - t.y) + abs(got.z - t.z) < 1e-9:
                    return ""
            except _TF_ERRORS:
                pass
            time.sleep(0.005)
        return f"the step's frame {child} did not reach tf within {_FRAME_WAIT:g} s"

    def _call_stop(self) -> None:
        try:
            self._stop()
        except (rospy.ServiceException, rospy.ROSException) as err:
            rospy.logerr("task_server: could not stop contact_control's move: %s", err)

    # the action

    def _load(self, goal: ExecuteTaskGoal) -> Task:
        if goal.task_yaml:
            return load_task(goal.task_yaml, "<goal task_yaml>", goal.overrides)
        if not goal.task or os.sep in goal.task or goal.task.startswith("."):
            raise TaskError(f"task {goal.task!r}: give a task's name in {self.tasks_dir}, or task_yaml")
        return load_task_file(os.path.join(self.tasks_dir, goal.task + ".yaml"), goal.overrides)

    def _execute(self, goal: ExecuteTaskGoal) -> None:
        if not self.busy.acquire(blocking=False):
            why = "refused: another task or path runs on this task_server"
            self._server.set_aborted(ExecuteTaskResult(outcome="refused", message=why), why)
            return
        try:
            self._execute_task(goal)
        finally:
            self.busy.release()

    def _execute_task(self, goal: ExecuteTaskGoal) -> None:
        try:
            task = self._load(goal)
        except TaskError as err:
            self._server.set_aborted(ExecuteTaskResult(outcome="refused", message=str(err)), str(err))
            return
        try:
            before = self._set_region(task.body_region) if task.body_region else ""
        except TaskError as err:
            self._server.set_aborted(ExecuteTaskResult(outcome="refused", message=str(err)), str(err))
            return
        answer = self._server.set_aborted, ExecuteTaskResult(outcome="refused", message="shutting down")
        try:
            answer = self._carry_out(task)
        finally:
            if before:  # the robot's own region back before the answer: the caller may act on it at once
                try:
                    self._set_region(before)
                except TaskError as err:
                    rospy.logerr("task_server: %s", err)
            send, result = answer
            send(result, result.message)

    def _set_region(self, region: str) -> str:
        """jog_arm's collaborative_region set to `region` (dynamic_reconfigure); the one it had.

        Raises:
            TaskError: jog_arm's reconfiguration is not there or refused it.
        """
        try:
            client = Client(self.s.jog_arm, timeout=self.s.status_timeout)
            try:
                before = str(client.get_configuration(timeout=self.s.status_timeout)["collaborative_region"])
                after = client.update_configuration({"collaborative_region": region})
            finally:
                client.close()
        except (rospy.ROSException, KeyError, TypeError) as err:
            raise TaskError(f"cannot set the body region {region!r} on {self.s.jog_arm}: {err}") from None
        if after.get("collaborative_region") != region:
            raise TaskError(f"{self.s.jog_arm} refused the body region {region!r}")
        rospy.loginfo("task_server: body region %s (was %s)", region, before)
        return before

    def _carry_out(self, task: Task) -> tuple[Callable[..., None], ExecuteTaskResult]:
        """Runs the task; how to answer (the action server's set_succeeded, _aborted or _preempted) and
        with what."""
        feedback, began = ExecuteTaskFeedback(), rospy.get_time()

        def publish(run: TaskRun, obs: Observation) -> None:
            feedback.step, feedback.elapsed = run.step_name, obs.t - began
            w = feedback.wrench
            w.force.x, w.force.y, w.force.z = obs.wrench[:3]
            w.torque.x, w.torque.y, w.torque.z = obs.wrench[3:]
            feedback.depth, feedback.search_radius = run.depth, run.search_radius
            self._server.publish_feedback(feedback)

        run, why = self.carry_out(task, self._server.is_preempt_requested, feedback=publish)
        if run is None:
            return self._server.set_aborted, ExecuteTaskResult(outcome="refused", message=why)
        result = self._result(run)
        return self.answer(self._server, run), result

    def carry_out(self, task: Task | Callable[[FloatArray], Task], preempted: Callable[[], bool],
                  watch: Callable[[TaskRun, Observation], None] | None = None,
                  feedback: Callable[[TaskRun, Observation], None] | None = None,
                  ) -> tuple[TaskRun | None, str]:
        """Runs `task` (or the one a builder makes from the tool's pose once it is known; a TaskError it
        raises refuses) until it ends, is `preempted` or the node shuts down; `watch` sees every observation
        after the run's update, `feedback` one in `rate / feedback_rate`. (the run, "") or (None, why it could
        not start)."""
        with self._lock:
            self._touched = self._released = False
            self._not_before = rospy.get_time()
        self._listen()
        try:
            return self._loop(task, preempted, watch, feedback)
        finally:
            self._unlisten()
            with self._lock:
                self._not_before = math.inf
                self._run = None

    def _loop(self, task: Task | Callable[[FloatArray], Task], preempted: Callable[[], bool],
              watch: Callable[[TaskRun, Observation], None] | None,
              feedback: Callable[[TaskRun, Observation], None] | None) -> tuple[TaskRun | None, str]:
        status, tool = self._wait_for_inputs()
        if status is None:
            return None, (f"no ~status from {self.cc} within {self.s.status_timeout:g} s: is "
                          "contact_control running?")
        if tool is None:
            return None, f"no transform {self.fixed_frame} -> {self.eef_frame}: the tool's pose is unknown"
        if not isinstance(task, Task):
            try:
                task = task(tool)
            except TaskError as err:
                return None, str(err)
        self._laws_at = math.inf
        run = TaskRun(task, self.s.path_horizon, self.s.path_horizon_step, self.eef_frame, self.step_frame)
        obs = self._observe(tool)
        self._apply(run, run.start(obs), obs)
        rate, every = rospy.Rate(self.s.rate), max(1, round(self.s.rate / self.s.feedback_rate))
        cycle = 0
        with self._lock:
            self._run = run
        while run.running and not rospy.is_shutdown():
            rate.sleep()
            tool = self._tool()
            if tool is None:
                self._apply(run, run.refused("the tool's pose is no longer available (tf)", obs), obs)
                break
            obs = self._observe(tool)
            if preempted():
                self._apply(run, run.cancel(obs), obs)
                break
            self._apply(run, run.update(obs), obs)
            if watch is not None:
                watch(run, obs)
            cycle += 1
            if feedback is not None and cycle % every == 0 and run.running:
                feedback(run, obs)
        if run.running:  # shutting down
            self._apply(run, run.cancel(obs), obs)
        r = run.result
        with self._lock:
            self._last = f"last task '{task.name}': {r.outcome}: {r.reason}"
        rospy.loginfo("task_server: task '%s' %s: %s", task.name, r.outcome, r.reason)
        return run, ""

    @staticmethod
    def answer(server: actionlib.SimpleActionServer, run: TaskRun) -> Callable[..., None]:
        """The action server's set_succeeded, _aborted or _preempted for how `run` ended."""
        outcome = run.result.outcome
        send: Callable[..., None] = server.set_preempted
        if outcome == SUCCEEDED:
            send = server.set_succeeded
        elif outcome in (FAILED, RUNNING):
            send = server.set_aborted
        return send

    def _result(self, run: TaskRun) -> ExecuteTaskResult:
        r = run.result
        result = ExecuteTaskResult(success=r.outcome == SUCCEEDED, outcome=r.outcome, message=r.reason)
        result.steps = list(r.step_times)
        result.step_times = [r.step_times[name] for name in result.steps]
        result.peak_force, result.peak_torque = r.peak_force, r.peak_torque
        if r.end_pose is not None:
            pose = result.end_pose
            pose.header.stamp, pose.header.frame_id = rospy.Time.now(), self.tf_prefix.add(self.fixed_frame)
            p, o = pose.pose.position, pose.pose.orientation
            p.x, p.y, p.z = (float(x) for x in r.end_pose[:3, 3])
            o.x, o.y, o.z, o.w = matrix_quaternion(r.end_pose[:3, :3].tolist())
        return result


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of `rosrun contact_tasks task_server`; 1 on a bad configuration."""
    rospy.init_node("task_server", argv=list(sys.argv if argv is None else argv))
    try:
        s = load_settings(rospy.get_param("~", {}))
    except TaskError as err:
        rospy.logfatal("task_server: bad configuration, not starting: %s", err)
        return 1
    cc = rospy.resolve_name(s.contact_control_node) + "/"
    fixed = str(rospy.get_param(cc + "fixed_frame", "base_link"))
    eef = str(rospy.get_param(cc + "eef_frame", "tool0"))
    tasks_dir = os.path.expanduser(s.tasks_dir) or os.path.join(rospkg.RosPack().get_path("contact_tasks"),
                                                                "tasks")
    TaskServer(s, fixed, eef, tasks_dir)
    rospy.loginfo("task_server: tasks in %s, tool pose %s in %s", tasks_dir, eef, fixed)
    rospy.spin()
    return 0
