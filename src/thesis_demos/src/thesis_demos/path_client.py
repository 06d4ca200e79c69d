"""The eighth demonstration's flow against a live stack: the path planned on the nominal cylinder goes to
contact_tasks' `~follow_path`; the tool's poses are recorded; the driver's `~surface` says where the part
truly was (thesis_demos.finishing judges it)."""

from __future__ import annotations

import threading

import actionlib
import dynamic_reconfigure.client
import numpy as np
import rospy
from compliant_control_msgs.msg import (
    FollowPathAtForceAction,
    FollowPathAtForceFeedback,
    FollowPathAtForceGoal,
)
from contact_control.frames import quaternion_matrix
from geometry_msgs.msg import Pose, PoseStamped

from thesis_demos.finishing import PathRecording
from thesis_demos.path_silence import silence_words
from thesis_demos.scenarios import PathDemo
from thesis_demos.stack_client import StackClient
from thesis_demos.surfaces import cylinder_path

__all__ = ["PathFlow"]

#: [s] beyond the path's own time, for the approach, the press and the answer: longer than the task's own
#: time limit adds (contact_tasks' path_task: its move to the start and 60 s), so a stalled arm is the
#: task's answer with the step it stalled in.
ANSWER_MARGIN = 90.0
_RESULT_FIELDS = ("length", "force_rms_error", "force_max", "contact_fraction", "normal_angle_rms",
                  "normal_angle_max", "lateral_error_rms", "lateral_error_max", "duration")


class PathFlow:
    """Runs a PathDemo from the start pose through `<tasks>/follow_path`."""

    def __init__(self, stack: StackClient, tasks: str, nominal_top: tuple[float, float, float]) -> None:
        """`nominal_top`: the cylinder's highest point as the model says (the obstacle's top centre)."""
        self._stack, self._tasks, self._top = stack, tasks, nominal_top
        self._lock = threading.Lock()
        self._feedback: list[tuple[float, str, float, float, float]] = []
        self._poses: list[tuple[float, np.ndarray, np.ndarray]] = []  # t, tip, tool's z
        self._frame = ""

    def _on_feedback(self, fb: FollowPathAtForceFeedback) -> None:
        with self._lock:
            self._feedback.append((rospy.get_time(), fb.step, fb.progress, fb.force, fb.normal_angle))

    def _on_pose(self, msg: PoseStamped) -> None:
        p, q = msg.pose.position, msg.pose.orientation
        R = np.asarray(quaternion_matrix(q.x, q.y, q.z, q.w))
        with self._lock:
            self._frame = msg.header.frame_id
            self._poses.append((msg.header.stamp.to_sec(), np.array([p.x, p.y, p.z]), R))

    def run(self, demo: PathDemo, sensor_frame: str, timeout: float = 60.0) -> PathRecording:
        """The path from the start pose, planned on the nominal cylinder.

        Raises:
            RuntimeError: The scene has no cylinder (the driver's `~surface`), or no task_server.
            TimeoutError: No answer within the path's time and ANSWER_MARGIN.
        """
        truth = rospy.get_param(f"{self._stack.names.driver}/surface", None)
        if not truth or truth.get("kind") != "cylinder":
            raise RuntimeError("the scene has no cylinder (launch it with fixture:=cylinder tool:=ball; make "
                               "demo does)")
        client = actionlib.SimpleActionClient(f"{self._tasks}/follow_path", FollowPathAtForceAction)
        if not client.wait_for_server(rospy.Duration(timeout)):
            raise RuntimeError(f"no task_server at {self._tasks}/follow_path")
        reconfigure = dynamic_reconfigure.client.Client(self._stack.names.contact_control, timeout=timeout)
        before = reconfigure.get_configuration(timeout=timeout)["normal_friction"]
        friction = truth.get("friction")  # the pad on this part: contact_control's normal law is told it
        sub = rospy.Subscriber(f"{self._stack.names.driver}/eef_pose", PoseStamped, self._on_pose,
                               queue_size=100, tcp_nodelay=True)
        try:
            if friction is not None:
                reconfigure.update_configuration({"normal_friction": float(friction)})
            self._stack.prepare(sensor_frame)
            self._stack.wait(lambda: bool(self._poses), timeout, "the tool's pose")
            with self._lock:
                start, frame = self._poses[-1][2], self._frame
            planned = cylinder_path(self._top, demo.radius, demo.length, start, middle=demo.middle)
            goal = FollowPathAtForceGoal(speed=demo.speed, force=demo.force)
            goal.path.header.frame_id = frame
            for row in planned:
                pose = PoseStamped()
                pose.pose = Pose()
                pose.pose.position.x, pose.pose.position.y, pose.pose.position.z = row[:3]
                o = pose.pose.orientation
                o.x, o.y, o.z, o.w = row[3:]
                goal.path.poses.append(pose)
            t0 = rospy.get_time()
            client.send_goal(goal, feedback_cb=self._on_feedback)
            limit = demo.length / demo.speed + ANSWER_MARGIN
            if not client.wait_for_result(rospy.Duration(limit)):
                client.cancel_goal()
                with self._lock:
                    last = self._feedback[-1][:4] if self._feedback else None
                raise TimeoutError(f"~follow_path gave no answer within {limit:g} s; "
                                   f"{silence_words(last, rospy.get_time())}")
            result = client.get_result()
        finally:
            sub.unregister()
            reconfigure.update_configuration({"normal_friction": before})
            reconfigure.close()
        self._stack.stop()
        return self._recording(result, truth, planned, t0)

    def _recording(self, result: object, truth: dict, planned: list[list[float]], t0: float) -> PathRecording:
        with self._lock:
            feedback, poses = list(self._feedback), list(self._poses)
        following = [f[0] for f in feedback if f[1] == "follow"]
        begin, end = (following[0], following[-1]) if following else (t0, t0)
        along = [p for p in poses if begin <= p[0] <= end]
        fb = [f for f in feedback if f[1] == "follow"]
        return PathRecording(
            outcome=result.outcome, message=result.message,  # type: ignore[attr-defined]
            result={name: float(getattr(result, name)) for name in _RESULT_FIELDS},
            nominal_top=self._top, truth=truth,
            feedback_t=np.array([f[0] - t0 for f in fb]), progress=np.array([f[2] for f in fb]),
            force=np.array([f[3] for f in fb]), angle=np.array([f[4] for f in fb]),
            planned=np.array([row[:3] for row in planned]),
            pose_t=np.array([p[0] - t0 for p in along]),
            tip=np.array([p[1] for p in along]).reshape(-1, 3),
            axis=np.array([p[2][:, 2] for p in along]).reshape(-1, 3),
        )
