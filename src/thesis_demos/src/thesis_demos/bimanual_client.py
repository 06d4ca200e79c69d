"""The ninth demonstration's flow against a live cell (thesis_demos.bimanual): the holder carries its plate to
where the cell file says and holds it with the spring law on Z; the presser's contact_tasks `~follow_path`
touches the plate, presses and slides along the cell file's line; the presser lifts off; the holder must come
back. Both arms through their public interfaces only, each in its namespace; the cell's tf tree (mujoco_cell
hangs each arm from `world`) places one arm's poses in the other's frame."""

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
from geometry_msgs.msg import PoseStamped
from mujoco_driver.cell_file import Bimanual

from thesis_demos.bimanual import (
    BIMANUAL_FORCE,
    BIMANUAL_SPEED,
    HOLD_TUNING,
    BimanualRecording,
    hold_laws,
    lift_laws,
    reach_laws,
)
from thesis_demos.path_silence import silence_words
from thesis_demos.stack_client import StackClient

__all__ = ["BimanualFlow"]

MOVE_TIMEOUT = 30.0  # [s] for the holder's reach and the presser's lift


class BimanualFlow:
    """Runs the demonstration with `holder` and `presser` (each a StackClient in its arm's namespace);
    `tasks`: the presser's task_server."""

    def __init__(self, holder: StackClient, presser: StackClient, tasks: str,
                 world_frame: str = "world") -> None:
        self._holder, self._presser, self._tasks, self._world = holder, presser, tasks, world_frame
        self._lock = threading.Lock()
        self._following: list[float] = []  # stamps of the feedback while the path server's step is `follow`
        self._last: tuple[float, str, float, float] | None = None  # the last feedback (path_silence)

    def _on_feedback(self, fb: FollowPathAtForceFeedback) -> None:
        now = rospy.get_time()
        with self._lock:
            self._last = (now, fb.step, fb.progress, fb.force)
            if fb.step == "follow":
                self._following.append(now)

    def run(self, spec: Bimanual, sensor_frame: str, timeout: float = 60.0) -> BimanualRecording:
        """The whole demonstration from both arms' start poses; both back there afterwards.

        Raises:
            RuntimeError: A law refused, or no task_server.
            TimeoutError: A move, the path or a settle that never ends.
        """
        holder = self._holder
        client = actionlib.SimpleActionClient(f"{self._tasks}/follow_path", FollowPathAtForceAction)
        if not client.wait_for_server(rospy.Duration(timeout)):
            raise RuntimeError(f"no task_server at {self._tasks}/follow_path")
        tuning = dynamic_reconfigure.client.Client(holder.names.contact_control, timeout=timeout)
        before = tuning.get_configuration(timeout=timeout)
        try:
            tuning.update_configuration(HOLD_TUNING)
            return self._run(client, spec, sensor_frame, timeout)
        except BaseException:
            client.cancel_all_goals()  # a flow cut short leaves both arms holding where they are
            self._presser.stop()
            self._holder.stop()
            raise
        finally:
            tuning.update_configuration({key: before[key] for key in HOLD_TUNING})
            tuning.close()

    def _run(self, client: actionlib.SimpleActionClient, spec: Bimanual, sensor_frame: str,
             timeout: float) -> BimanualRecording:
        holder, presser = self._holder, self._presser
        # A cell just launched: each arm's tf may come seconds after its topics.
        for stack in (holder, presser):
            stack.wait(lambda s=stack: s.sees(self._world, sensor_frame), timeout,
                       f"tf from {self._world} to {stack.names.contact_control}'s tool and sensor")
        presser.start_tip()
        holder.prepare(sensor_frame)
        target = holder.in_base(self._world, np.asarray(spec.plate, dtype=float))
        reaching = holder.send_laws(reach_laws(target - holder.tool_pose()[0]))
        holder.wait_move_end(reaching, MOVE_TIMEOUT, "the holder to reach where it holds the plate")
        holder.stop()
        holder.settle()
        holder.tare()
        holder.send_laws(hold_laws())
        holder.settle()
        held_z = float(holder.tip()[2])
        baseline_t = presser.prepare(sensor_frame)
        top = holder.world_pose(self._world)[0][2]  # the plate's top: the holder's tool tip
        # The plate is flat and level: the path's orientation (the tool as it starts), no normal law, which on
        # this friction (about 1) would read the normal leant by the slide.
        goal = FollowPathAtForceGoal(speed=BIMANUAL_SPEED, force=BIMANUAL_FORCE, orientation="path")
        goal.path.header.frame_id = self._world
        orientation = presser.world_pose(self._world)[1]
        for x, y in (spec.press, (spec.press[0] + spec.slide[0], spec.press[1] + spec.slide[1])):
            pose = PoseStamped()
            pose.pose.position.x, pose.pose.position.y, pose.pose.position.z = x, y, top
            o = pose.pose.orientation
            o.x, o.y, o.z, o.w = orientation
            goal.path.poses.append(pose)
        sent = rospy.get_time()  # the presser's sensor before it: the contact force's zero
        client.send_goal(goal, feedback_cb=self._on_feedback)
        limit = float(np.hypot(*spec.slide)) / BIMANUAL_SPEED + timeout
        if not client.wait_for_result(rospy.Duration(limit)):
            client.cancel_goal()
            with self._lock:
                last = self._last
            raise TimeoutError(f"~follow_path gave no answer within {limit:g} s; "
                               f"{silence_words(last, rospy.get_time())}")
        result = client.get_result()
        presser.stop()
        lifting = presser.send_laws(lift_laws())
        presser.wait_move_end(lifting, MOVE_TIMEOUT, "the presser's lift")
        presser.stop()
        # Back where it held: still to 0.1 mm over 1 s (the spring's time constant is 1 / (s k) = 0.33 s).
        holder.wait(lambda: holder.still(1.0, 1e-4), 30.0, "the holder to come back")
        returned_z = float(holder.tip()[2])
        with self._lock:
            following = list(self._following)
        t0 = following[0] if following else rospy.get_time()
        slide_end = (following[-1] - t0) if following else 0.0
        pressed = presser.recording(sent, baseline_t, {}, None)
        holder_t, holder_pose = holder.pose.arrays(sent)
        holder.stop()
        presser.start_tip()
        holder.start_tip()
        return BimanualRecording(
            force_t=pressed.wrench_t - (t0 - sent), force=pressed.contact_force[:, 2],
            holder_t=holder_t - (t0 - sent), holder_z=holder_pose[:, 2], slide_end=slide_end, held_z=held_z,
            returned_z=returned_z, outcome=result.outcome, message=result.message)
