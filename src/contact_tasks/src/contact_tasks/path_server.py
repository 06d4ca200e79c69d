"""task_server's `~follow_path` (compliant_control_msgs/FollowPathAtForce): a path at a force, run as a task
(`path_task`) by the node's task loop, measured along the way (`PathMetrics`). See the package README,
*Paths at a force*.
"""

from __future__ import annotations

import math
import threading
from collections.abc import Callable
from typing import Protocol

import actionlib
import numpy as np
import rospy
import tf2_ros
from compliant_common.tf_prefix import TfPrefix
from compliant_common.typedefs import FloatArray
from compliant_control_msgs.msg import (
    FollowPathAtForceAction,
    FollowPathAtForceFeedback,
    FollowPathAtForceGoal,
    FollowPathAtForceResult,
)
from contact_control.frames import matrix_quaternion, quaternion_matrix

from contact_tasks.params import TaskServerSettings
from contact_tasks.path import PosePath
from contact_tasks.path_task import RAMP, PathGoal, PathMetrics, path_task
from contact_tasks.run import SUCCEEDED, Observation, TaskRun
from contact_tasks.task import Task, TaskError

__all__ = ["FollowPathServer"]

_TF_ERRORS = (tf2_ros.LookupException, tf2_ros.ConnectivityException, tf2_ros.ExtrapolationException,
              tf2_ros.TransformException)


def goal_poses(goal: FollowPathAtForceGoal) -> tuple[str, list[list[float]]]:
    """The goal's frame and poses (x, y, z, qx, qy, qz, qw): the Path's, or the PoseArray's without one."""
    if goal.path.poses:
        frame = goal.path.header.frame_id
        poses = [p.pose for p in goal.path.poses]
    else:
        frame, poses = goal.poses.header.frame_id, list(goal.poses.poses)
    rows = [[p.position.x, p.position.y, p.position.z,
             p.orientation.x, p.orientation.y, p.orientation.z, p.orientation.w] for p in poses]
    return frame.lstrip("/"), rows


Watch = Callable[[TaskRun, Observation], None]


class TaskLoop(Protocol):
    """What the path server needs of task_server's node (`node.TaskServer`)."""

    s: TaskServerSettings
    fixed_frame: str
    cc: str
    tf: tf2_ros.Buffer
    tf_prefix: TfPrefix
    busy: threading.Lock

    def carry_out(self, task: Task | Callable[[FloatArray], Task], preempted: Callable[[], bool],
                  watch: Watch | None = None,
                  feedback: Watch | None = None) -> tuple[TaskRun | None, str]: ...

    def answer(self, server: actionlib.SimpleActionServer, run: TaskRun) -> Callable[..., None]: ...


class FollowPathServer:
    """`~follow_path` on a `TaskServer`: one goal at a time, shared with `~execute`."""

    def __init__(self, node: TaskLoop) -> None:
        self._node = node
        self._server = actionlib.SimpleActionServer("~follow_path", FollowPathAtForceAction, self._execute,
                                                    auto_start=False)
        self._server.start()

    def _refuse(self, why: str) -> None:
        self._server.set_aborted(FollowPathAtForceResult(outcome="refused", message=why), why)

    def _execute(self, goal: FollowPathAtForceGoal) -> None:
        if not self._node.busy.acquire(blocking=False):
            self._refuse("refused: another task or path runs on this task_server")
            return
        try:
            self._follow(goal)
        finally:
            self._node.busy.release()

    def _to_fixed(self, frame: str, rows: list[list[float]]) -> list[list[float]]:
        """The poses in contact_control's fixed frame (tf, the latest transform)."""
        node = self._node
        if not frame or node.tf_prefix.bare(frame) == node.fixed_frame:
            return rows
        try:
            tf = node.tf.lookup_transform(node.tf_prefix.add(node.fixed_frame), frame, rospy.Time(0),
                                          rospy.Duration(node.s.status_timeout))
        except _TF_ERRORS as err:
            raise TaskError(f"path.header.frame_id: no transform {node.fixed_frame} -> {frame}: "
                            f"{err}") from None
        p, q = tf.transform.translation, tf.transform.rotation
        R = np.asarray(quaternion_matrix(q.x, q.y, q.z, q.w))
        out = []
        for row in rows:
            position = R @ np.asarray(row[:3]) + (p.x, p.y, p.z)
            turned = R @ np.asarray(quaternion_matrix(*row[3:7]))
            out.append([*(float(x) for x in position), *matrix_quaternion(turned.tolist())])
        return out

    def _follow(self, goal: FollowPathAtForceGoal) -> None:
        frame, rows = goal_poses(goal)
        measured: list[PathMetrics] = []

        def build(tool: FloatArray) -> Task:
            want = PathGoal(self._to_fixed(frame, rows), speed=goal.speed or 0.01, force=goal.force or 10.0,
                            forces=tuple(goal.segment_forces), orientation=goal.orientation or "normal",
                            standoff=goal.standoff or 0.02)
            task = path_task(want, tool)
            path = PosePath(want.poses, want.speed, ramp=RAMP)
            # the friction contact_control's normal law takes out (live-tunable: read per goal)
            mu = float(rospy.get_param(self._node.cc + "/normal_friction", 0.0))
            measured.append(PathMetrics(path, want.segment_forces(path.segments), mu))
            return task

        latest = [0.0, 0.0, 0.0]  # force, path error, angle of the last sample along the path

        def watch(run: TaskRun, obs: Observation) -> None:
            point = run.path_point
            if run.running and run.step_name == "follow" and point is not None and measured:
                latest[:] = measured[0].add(obs.t, obs.tool, obs.wrench, point.segment)

        feedback = FollowPathAtForceFeedback()

        def publish(run: TaskRun, obs: Observation) -> None:
            feedback.step = run.step_name
            point = run.path_point
            following = run.step_name == "follow" and point is not None and measured
            feedback.progress = point.arc / measured[0].path.length if following and point else 0.0
            if not following:
                latest[:] = [-float(obs.wrench[2]) if run.step_name in ("touch", "press") else 0.0, 0.0, 0.0]
            feedback.force, feedback.path_error = latest[0], latest[1]
            feedback.normal_angle = math.degrees(latest[2])
            self._server.publish_feedback(feedback)

        run, why = self._node.carry_out(build, self._server.is_preempt_requested, watch, publish)
        if run is None:
            self._refuse(why)
            return
        r = run.result
        result = FollowPathAtForceResult(success=r.outcome == SUCCEEDED, outcome=r.outcome, message=r.reason)
        if measured:
            result.length = measured[0].path.length
            for key, value in measured[0].summary().items():
                setattr(result, key, value)
        rospy.loginfo("task_server: path of %.3f m %s: force RMS error %.2f N, max %.1f N, contact %.3f, "
                      "normal angle RMS %.2f deg, lateral max %.2f mm", result.length, r.outcome,
                      result.force_rms_error, result.force_max, result.contact_fraction,
                      result.normal_angle_rms,
                      result.lateral_error_max * 1e3)
        self._node.answer(self._server, run)(result, result.message)
