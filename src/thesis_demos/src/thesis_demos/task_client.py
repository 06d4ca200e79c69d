"""The seventh demonstration's flow against a live stack: contact_tasks' task_server runs the task; the
driver's `~hole_pose` says where the hole truly was (thesis_demos.insertion judges it)."""

from __future__ import annotations

import threading

import actionlib
import numpy as np
import rospy
from compliant_control_msgs.msg import ExecuteTaskAction, ExecuteTaskFeedback, ExecuteTaskGoal

from thesis_demos.insertion import TaskDemo, TaskRecording
from thesis_demos.stack_client import StackClient

__all__ = ["TaskFlow"]

#: [s] beyond the task's own limit, for the retract and the answer.
ANSWER_MARGIN = 60.0


class TaskFlow:
    """Runs a TaskDemo from the start pose through `<tasks>/execute` and records its feedback."""

    def __init__(self, stack: StackClient, tasks: str, nominal: tuple[float, float] | None) -> None:
        """`nominal`: where the task was told the hole is (the block's top centre); None: the true hole."""
        self._stack, self._tasks, self._nominal = stack, tasks, nominal
        self._lock = threading.Lock()
        self._feedback: list[tuple[float, str, float, float]] = []

    def _on_feedback(self, fb: ExecuteTaskFeedback) -> None:
        f = fb.wrench.force
        magnitude = float(np.linalg.norm((f.x, f.y, f.z)))
        with self._lock:
            self._feedback.append((rospy.get_time(), fb.step, fb.depth, magnitude))

    def run(self, demo: TaskDemo, sensor_frame: str, timeout: float = 60.0) -> TaskRecording:
        """The task from the start pose, told only where the plate's top would be at the nominal hole.

        Raises:
            RuntimeError: The scene has no hole (the driver has no `~hole_pose`), or no task_server.
            TimeoutError: No answer within the task's time and ANSWER_MARGIN.
        """
        hole = rospy.get_param(f"{self._stack.names.driver}/hole_pose", None)
        if hole is None:
            raise RuntimeError("the scene has no hole fixture (launch it with fixture:=hole tool:=peg; "
                               "make demo does)")
        client = actionlib.SimpleActionClient(f"{self._tasks}/execute", ExecuteTaskAction)
        if not client.wait_for_server(rospy.Duration(timeout)):
            raise RuntimeError(f"no task_server at {self._tasks}/execute")
        self._stack.prepare(sensor_frame)
        surface = float(self._stack.tip()[2]) - float(hole[2])
        t0 = rospy.get_time()
        client.send_goal(ExecuteTaskGoal(task=demo.task, overrides=f"{{surface: {surface:.4f}}}"),
                         feedback_cb=self._on_feedback)
        if not client.wait_for_result(rospy.Duration(demo.within + ANSWER_MARGIN)):
            client.cancel_goal()
            raise TimeoutError(f"task {demo.task} gave no answer within {demo.within + ANSWER_MARGIN:g} s")
        result = client.get_result()
        self._stack.stop()
        with self._lock:
            feedback = list(self._feedback)
        pose_t, pose = self._stack.pose.arrays(t0)
        return TaskRecording(
            outcome=result.outcome, message=result.message, steps=list(result.steps),
            step_times=list(result.step_times), peak_force=result.peak_force, peak_torque=result.peak_torque,
            hole=tuple(float(v) for v in hole),  # type: ignore[arg-type]
            nominal=self._nominal or (float(hole[0]), float(hole[1])),
            feedback_t=np.array([f[0] - t0 for f in feedback]), feedback_step=[f[1] for f in feedback],
            depth=np.array([f[2] for f in feedback]), force=np.array([f[3] for f in feedback]),
            pose_t=pose_t, pose=pose,
        )
