"""`named_pose_server`: moves the arm to a named pose on request, through the driver's JointTrajectory input.

Thin adapter over `poses` and `profile`: reads `~config` (the robot package's config/named_poses.yaml;
without it `~poses`, `~max_velocity`, `~max_acceleration`) and `robot_description`, listens to
`joint_states` and contact_control's `~status`, and serves `~move_to` (MoveToNamedPose).
The answer comes when the arm has arrived (every joint within `~goal_tolerance`) or the move failed.
"""

from __future__ import annotations

import threading
import time

import numpy as np
import rospy
import yaml
from compliant_control_msgs.msg import ContactControlStatus
from compliant_control_msgs.srv import MoveToNamedPose, MoveToNamedPoseResponse
from sensor_msgs.msg import JointState
from trajectory_msgs.msg import JointTrajectory, JointTrajectoryPoint

from named_poses.params import FILE_KEYS, load_settings
from named_poses.poses import NamedPoses, PoseError, urdf_joints
from named_poses.profile import ProfileError, plan_move

__all__ = ["NamedPoseServer", "main"]


class NamedPoseServer:
    """The ROS side: state in, trajectory out, one move at a time."""

    def __init__(self) -> None:
        urdf = rospy.get_param("robot_description")
        params = rospy.get_param("~", {})
        try:
            settings = load_settings(params)
        except ValueError as exc:
            raise PoseError(str(exc)) from None
        config = settings.config
        if config:  # the file itself: a dict loaded onto the parameter server merges with a previous robot's
            try:
                with open(config, encoding="utf-8") as handle:
                    data = yaml.safe_load(handle) or {}
            except (OSError, yaml.YAMLError) as exc:
                raise PoseError(f"~config: cannot read {config}: {exc}") from exc
        else:
            data = {key: params[key] for key in FILE_KEYS if key in params}
        self.poses = NamedPoses.from_dict(data, urdf_joints(urdf))
        self.tolerance = settings.goal_tolerance  # [rad]
        self.settle_time = settings.settle_time  # [s] after the planned end
        self.state_wait = settings.state_wait  # [s] for a first joint state, right after start-up
        self._lock = threading.Lock()
        self._state_seen = threading.Condition(self._lock)
        self._busy = threading.Lock()
        self._positions: dict[str, float] = {}
        self._status: ContactControlStatus | None = None
        self._pub = rospy.Publisher(
            settings.trajectory_topic, JointTrajectory, queue_size=1,
            tcp_nodelay=True,
        )
        self._states_topic = rospy.resolve_name(settings.joint_states_topic)
        rospy.Subscriber(settings.joint_states_topic, JointState, self._on_joints,
                         queue_size=1, tcp_nodelay=True)
        rospy.Subscriber(settings.contact_control_status,
                         ContactControlStatus, self._on_status, queue_size=1)
        rospy.Service("~move_to", MoveToNamedPose, self._move_to)
        rospy.loginfo(
            "named_pose_server: poses %s for joints %s", sorted(self.poses.poses), list(self.poses.joints)
        )

    def _on_joints(self, msg: JointState) -> None:
        with self._lock:
            self._positions.update(zip(msg.name, msg.position, strict=False))
            self._state_seen.notify_all()

    def _on_status(self, msg: ContactControlStatus) -> None:
        with self._lock:
            self._status = msg

    def _current(self) -> np.ndarray | None:
        with self._lock:
            if not all(j in self._positions for j in self.poses.joints):
                return None
            return np.array([self._positions[j] for j in self.poses.joints])

    def _first_state(self) -> np.ndarray | None:
        """The current joints, waiting up to `~state_wait` for them: a request may come before the driver's
        first state has reached this node (its subscription connects after the service is up)."""
        deadline = time.monotonic() + self.state_wait
        with self._state_seen:
            while not all(j in self._positions for j in self.poses.joints):
                left = deadline - time.monotonic()
                if left <= 0.0 or rospy.is_shutdown():
                    return None
                self._state_seen.wait(min(left, 0.1))
        return self._current()

    def _contact_move_running(self) -> bool:
        with self._lock:
            status = self._status
        return bool(status and (status.move_active or status.reacting))

    def _move_to(self, req: MoveToNamedPose) -> MoveToNamedPoseResponse:
        if not self._busy.acquire(blocking=False):
            return self._refuse("another named-pose move is running")
        try:
            return self._run(req)
        finally:
            self._busy.release()

    @staticmethod
    def _refuse(reason: str) -> MoveToNamedPoseResponse:
        rospy.logwarn("named_pose_server: refused: %s", reason)
        return MoveToNamedPoseResponse(success=False, message=reason)

    def _run(self, req: MoveToNamedPose) -> MoveToNamedPoseResponse:
        scale = req.speed_scale or 1.0
        if not 0.0 < scale <= 1.0:
            return self._refuse(f"speed_scale must be in (0, 1], got {req.speed_scale}")
        if self._contact_move_running():
            return self._refuse(
                "a contact move is running (contact_control ~status move_active): stop it first "
                "(rosservice call /contact_control_node/stop)"
            )
        current = self._first_state()
        if current is None:
            return self._refuse(
                f"no joint state for {list(self.poses.joints)} within {self.state_wait:g} s "
                f"(is the driver publishing {self._states_topic}?)"
            )
        try:
            goal = self.poses.goal(req.name, current)
            move = plan_move(
                current, goal, self.poses.max_velocity * scale, self.poses.max_acceleration * scale
            )
        except (PoseError, ProfileError) as exc:
            return self._refuse(str(exc))
        msg = JointTrajectory()
        msg.joint_names = list(self.poses.joints)
        for t, q, v in zip(move.times, move.positions, move.velocities, strict=True):
            msg.points.append(JointTrajectoryPoint(
                positions=q.tolist(), velocities=v.tolist(), time_from_start=rospy.Duration.from_sec(float(t))
            ))
        if move.duration > 0.0:
            self._pub.publish(msg)  # stamp 0: the driver starts it now
        rospy.loginfo("named_pose_server: to %r in %.2f s", req.name, move.duration)
        deadline = time.monotonic() + move.duration + self.settle_time
        while time.monotonic() < deadline and not rospy.is_shutdown():
            now = self._current()
            if now is not None and float(np.max(np.abs(now - goal))) <= self.tolerance:
                return MoveToNamedPoseResponse(
                    success=True, message=f"at {req.name!r} after a {move.duration:.2f} s move"
                )
            time.sleep(0.01)
        now = self._current()
        error = float(np.max(np.abs(now - goal))) if now is not None else float("nan")
        return self._refuse(f"did not reach {req.name!r}: largest joint error {error:.3f} rad")


def main() -> int:
    """Node entry point."""
    rospy.init_node("named_poses")
    try:
        NamedPoseServer()
    except (PoseError, KeyError) as exc:
        rospy.logfatal("named_pose_server: %s", exc)
        return 1
    rospy.spin()
    return 0
