"""`named_pose_server`: moves the arm to a named pose on request, through the driver's JointTrajectory input.

Thin adapter over `poses` and `profile`: reads `~config` (the robot package's config/named_poses.yaml;
without it `~poses`, `~max_velocity`, `~max_acceleration`) and `robot_description`, listens to
`joint_states` and contact_control's `~status`, and serves `~move_to` (MoveToNamedPose).
The answer comes when the arm has arrived (every joint within `~goal_tolerance`) or the move failed.
"""

from __future__ import annotations

import contextlib
import threading
import time
from collections.abc import Callable, Iterator
from typing import NamedTuple

import numpy as np
import rosgraph
import rospy
import yaml
from compliant_common.diagnostics import OK, WARN, Report
from compliant_common.ros_diagnostics import DiagnosticsPublisher
from compliant_control_msgs.msg import ContactControlStatus
from compliant_control_msgs.srv import (
    MoveToJoints,
    MoveToJointsRequest,
    MoveToJointsResponse,
    MoveToNamedPose,
    MoveToNamedPoseResponse,
)
from controller_manager_msgs.srv import ListControllers, SwitchController, SwitchControllerRequest
from jog_arm.body_regions import max_speed, region_named
from jog_arm.kinematics import KinematicsError
from sensor_msgs.msg import JointState
from std_msgs.msg import String
from std_srvs.srv import Trigger
from trajectory_msgs.msg import JointTrajectory, JointTrajectoryPoint

from named_poses.follow_server import FollowServer
from named_poses.params import FILE_KEYS, load_settings
from named_poses.path_cap import PathCap
from named_poses.poses import NamedPoses, PoseError, urdf_joints
from named_poses.profile import MotionProfileError, plan_move
from named_poses.switching import Controller, Switch, SwitchError, controller_of, plan_switch

JOINTS_WARN = 1.0  # [s] no joint state for longer: WARN on /diagnostics (a move would be refused)

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
        self._status_rx = -1.0  # monotonic time of the last status received
        self._status_seen = threading.Condition(self._lock)
        self._status_topic = rospy.resolve_name(settings.contact_control_status)
        self._pub = rospy.Publisher(
            settings.trajectory_topic, JointTrajectory, queue_size=1,
            tcp_nodelay=True,
        )
        self._states_topic = rospy.resolve_name(settings.joint_states_topic)
        self._controller = controller_of(settings.trajectory_topic)
        self._manager = rospy.resolve_name(settings.controller_manager) if settings.controller_manager else ""
        self._jog = rospy.resolve_name(settings.jog_arm) if settings.jog_arm else ""
        # The collaborative speed cap: jog_arm's tip frame (else the last pose joint's), region and payload.
        tip = rospy.get_param(f"{self._jog}/ee_frame_name", "") if self._jog else ""
        try:
            self._path_cap = PathCap(urdf, list(self.poses.joints), tip or self.poses.joints[-1])
        except KinematicsError as exc:
            raise PoseError(f"the collaborative speed cap's tip ({self._jog}/ee_frame_name): {exc}") from None
        # The joint states are listened to only while a move is asked for and runs (`listening`): at the
        # driver's 500 Hz they cost this node 3 % of a core and the driver a socket write each, for nothing
        # while idle. Subscribing takes ~10-50 ms, which `~state_wait` covers.
        self._states_sub: rospy.Subscriber | None = None
        self._listeners = 0
        self._listen_lock = threading.Lock()
        rospy.Subscriber(settings.contact_control_status,
                         ContactControlStatus, self._on_status, queue_size=1)
        self._robot_stop = ""  # why the robot stopped by itself (jog_arm's ~robot_stop), '' while it runs
        if self._jog:
            rospy.Subscriber(f"{self._jog}/robot_stop", String, self._on_robot_stop, queue_size=5)
        self._joints_rx = -1.0  # monotonic time of the last joint state
        self._moving = ""  # the move running ('' when none)
        self._last_answer = "none yet"
        self._health = DiagnosticsPublisher(self._health_report)
        rospy.Service("~move_to", MoveToNamedPose, self._move_to)
        rospy.Service("~move_to_joints", MoveToJoints, self._move_to_joints)
        self._follow = FollowServer(self, settings, urdf_joints(urdf))
        rospy.loginfo(
            "named_pose_server: poses %s for joints %s", sorted(self.poses.poses), list(self.poses.joints)
        )

    def _on_robot_stop(self, msg: String) -> None:
        with self._lock:
            self._robot_stop = msg.data

    @contextlib.contextmanager
    def listening(self) -> Iterator[None]:
        """The joint states subscribed while the block runs (nested blocks share one subscription); the
        positions heard before are forgotten, so a move starts from a state received after its request."""
        with self._listen_lock:
            self._listeners += 1
            if self._listeners == 1:
                with self._lock:
                    self._positions.clear()
                    self._joints_rx = -1.0
                self._states_sub = rospy.Subscriber(self._states_topic, JointState, self._on_joints,
                                                    queue_size=1, tcp_nodelay=True)
        try:
            yield
        finally:
            with self._listen_lock:
                self._listeners -= 1
                if self._listeners == 0 and self._states_sub is not None:
                    self._states_sub.unregister()
                    self._states_sub = None

    def _on_joints(self, msg: JointState) -> None:
        with self._lock:
            self._joints_rx = time.monotonic()
            self._positions.update(zip(msg.name, msg.position, strict=False))
            self._state_seen.notify_all()

    def _health_report(self) -> Report:
        """/diagnostics: the move running, the joint states' age (WARN past JOINTS_WARN: a move would wait),
        the last answer."""
        report = Report(rospy.get_name())
        listening = self._states_sub is not None
        age = time.monotonic() - self._joints_rx if self._joints_rx >= 0.0 else None
        if listening and (age is None or age > JOINTS_WARN):
            what = "no joint state yet" if age is None else f"no joint state for {age:.1f} s"
            report.check(WARN, f"{what} on {self._states_topic}: the move waits for one")
        report.check(OK, f"moving to {self._moving}" if self._moving else "idle")
        report.value("joint state age [s]", "listened to during moves only" if not listening
                     else "none yet" if age is None else f"{age:.3f}")
        report.value("last move", self._last_answer)
        report.value("poses", ", ".join(sorted(self.poses.poses)))
        return report

    def _on_status(self, msg: ContactControlStatus) -> None:
        with self._lock:
            self._status = msg
            self._status_rx = time.monotonic()
            self._status_seen.notify_all()

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

    def _status_published(self) -> bool:
        """Whether the master knows a publisher of contact_control's status (rosgraph's public API)."""
        try:
            topics = rosgraph.Master(rospy.get_name()).getPublishedTopics("")
        except (rosgraph.MasterException, OSError):  # no master answer: decide on what this node has heard
            return self._status is not None
        return any(topic == self._status_topic for topic, _type in topics)

    def _contact_move_running(self) -> bool | None:
        """Whether a contact move runs, from a status received after this question; None if contact_control
        publishes its status but none came within `~state_wait`. Without contact_control: False. A status
        heard before the question is not enough: the move may have started since, or (a fresh start) this
        node may not be connected yet."""
        if not self._status_published():
            return False
        asked = time.monotonic()
        deadline = asked + self.state_wait
        with self._status_seen:
            while self._status_rx < asked:
                left = deadline - time.monotonic()
                if left <= 0.0 or rospy.is_shutdown():
                    return None
                self._status_seen.wait(min(left, 0.1))
            status = self._status
        return bool(status and (status.move_active or status.reacting))

    def _move_to(self, req: MoveToNamedPose) -> MoveToNamedPoseResponse:
        if not self._busy.acquire(blocking=False):
            return self._refuse("another named-pose move is running")
        try:
            return self._run(repr(req.name), req.speed_scale,
                             lambda current: self.poses.goal(req.name, current))
        finally:
            self._busy.release()

    def _move_to_joints(self, req: MoveToJointsRequest) -> MoveToJointsResponse:
        """compliant_control_msgs/MoveToJoints: the same move to given joint positions (a program's start)."""
        if not self._busy.acquire(blocking=False):
            return MoveToJointsResponse(success=False, message="another named-pose move is running")
        label = req.label or "the given joint positions"
        try:
            answer = self._run(label, req.speed_scale,
                               lambda _current: self.poses.goal_of(req.joint_names, req.positions, label))
        finally:
            self._busy.release()
        return MoveToJointsResponse(success=answer.success, message=answer.message)

    @staticmethod
    def _refuse(reason: str) -> MoveToNamedPoseResponse:
        rospy.logwarn("named_pose_server: refused: %s", reason)
        return MoveToNamedPoseResponse(success=False, message=reason)

    def _run(
        self, name: str, speed_scale: float, make_goal: Callable[[np.ndarray], np.ndarray]
    ) -> MoveToNamedPoseResponse:
        """A joint move to `make_goal(current)` (named `name` in the answers and the log)."""
        self._moving = name
        try:
            with self.listening():
                answer = self._run_move(name, speed_scale, make_goal)
        finally:
            self._moving = ""
        self._last_answer = ("" if answer.success else "refused or failed: ") + answer.message
        return answer

    def _run_move(
        self, name: str, speed_scale: float, make_goal: Callable[[np.ndarray], np.ndarray]
    ) -> MoveToNamedPoseResponse:
        scale = speed_scale or 1.0
        if not 0.0 < scale <= 1.0:
            return self._refuse(f"speed_scale must be in (0, 1], got {speed_scale}")
        why, current = self.ready()
        if current is None:
            return self._refuse(why)
        region = rospy.get_param(f"{self._jog}/collaborative_region", "hand") if self._jog else "hand"
        payload = rospy.get_param(f"{self._jog}/collaborative_payload", 0.0) if self._jog else 0.0
        try:
            goal = make_goal(current)
            cap = self._path_cap.limit(region, payload, current, goal)
            limits = (self.poses.max_velocity * scale, self.poses.max_acceleration * scale)
            move = plan_move(current, goal, *limits, max_path_speed=cap.speed)
            capped = move.duration > plan_move(current, goal, *limits).duration + 1e-9
        except (PoseError, MotionProfileError, ValueError) as exc:
            return self._refuse(str(exc))
        msg = JointTrajectory()
        msg.joint_names = list(self.poses.joints)
        for t, q, v in zip(move.times, move.positions, move.velocities, strict=True):
            msg.points.append(JointTrajectoryPoint(
                positions=q.tolist(), velocities=v.tolist(), time_from_start=rospy.Duration.from_sec(float(t))
            ))
        switch, paused = None, False
        if move.duration > 0.0:
            try:
                paused = self._pause_jog()
            except SwitchError as exc:
                return self._refuse(str(exc))
            try:
                switch = self._switch_on()
            except SwitchError as exc:
                return self._refuse(str(exc) + self._resume_jog(paused))
        back = _Switched(True, "")
        try:
            silent = self.trajectory_listener() if move.duration > 0.0 else ""
            answer = self._refuse(silent) if silent else self._move(name, goal, move.duration, msg)
        finally:
            if switch is not None:
                back = self._switch(switch.undo())
            resumed = self._resume_jog(paused)
        if isinstance(answer, str):  # the robot stopped: named after the clean-up, by when jog_arm names
            # its cause (a UR's safety mode may arrive after its consequence, the program's stop)
            answer = self._refuse(f"stopped on the way to {name}: {self._robot_stop or answer}")
        if switch is not None:
            note = f"; switched {list(switch.start)} on for the move (stopping {list(switch.stop)})"
            answer.message += note + (", then back" if back else f"; switching back failed: {back.reason}")
        answer.message += resumed
        if capped:
            tip_speed = max_speed(region_named(region), cap.robot_mass)
            answer.message += (f"; slowed to the collaborative speed cap ({tip_speed:.2f} m/s at the tip "
                               f"toward the {region}, ISO/TS 15066)")
        return answer

    def ready(self) -> tuple[str, np.ndarray | None]:
        """The joints now, or why no move may start ('', joints): the robot stopped by itself, a contact move
        running (or no status to tell), no joint state within `~state_wait`."""
        if self._robot_stop:
            return f"{self._robot_stop}: recover it first ({self._jog}/recover)", None
        running = self._contact_move_running()
        if running is None:
            return (f"no status from contact_control within {self.state_wait:g} s although it publishes "
                    f"{self._status_topic}: cannot tell whether a contact move runs"), None
        if running:
            return ("a contact move is running (contact_control ~status move_active): stop it first "
                    "(rosservice call /contact_control_node/stop)"), None
        current = self._first_state()
        if current is None:
            return (f"no joint state for {list(self.poses.joints)} within {self.state_wait:g} s "
                    f"(is the driver publishing {self._states_topic}?)"), None
        return "", current

    def trajectory_listener(self) -> str:
        """'' once the driver subscribes to the trajectory topic (waiting up to `~state_wait`), else why not:
        a trajectory published before its subscription has connected (right after start-up, or the
        controller just switched on) is lost, and the arm would not move at all."""
        deadline = time.monotonic() + self.state_wait
        while self._pub.get_num_connections() == 0:
            if time.monotonic() >= deadline or rospy.is_shutdown():
                return (f"nothing subscribes to {self._pub.resolved_name} within {self.state_wait:g} s "
                        "(is the driver's trajectory controller running?)")
            time.sleep(0.01)
        return ""

    # --- jog_arm pause (README, Jogging during a move) ---
    def _pause_jog(self) -> bool:
        """Pauses jog_arm for the move if it runs (asked of the master, no waiting); True if this move paused
        it. Its answer comes once it is at rest and silent, so nothing of its follows the trajectory.

        Raises:
            SwitchError: It runs but the pause failed.
        """
        if not self._jog or not _served(self._jog + "/pause"):
            return False
        try:
            answer = rospy.ServiceProxy(self._jog + "/pause", Trigger)()
        except (rospy.ServiceException, rospy.ROSException) as exc:
            raise SwitchError(f"could not pause {self._jog} for the move: {exc}") from exc
        return not answer.message.startswith("already paused")

    def _resume_jog(self, paused: bool) -> str:
        """Resumes jog_arm if this move paused it; a note for the answer."""
        if not paused:
            return ""
        try:
            rospy.ServiceProxy(self._jog + "/resume", Trigger)()
        except (rospy.ServiceException, rospy.ROSException) as exc:
            rospy.logerr("named_pose_server: could not resume %s: %s", self._jog, exc)
            return f"; {self._jog} paused for the move, resuming it failed: {exc} (call {self._jog}/resume)"
        return f"; {self._jog} paused for the move, then resumed"

    def _move(
        self, name: str, goal: np.ndarray, duration: float, msg: JointTrajectory
    ) -> MoveToNamedPoseResponse | str:
        """Sends the trajectory and waits for the arm to arrive; the robot's stop as jog_arm first named it
        if it stopped on the way."""
        if duration > 0.0:
            self._pub.publish(msg)  # stamp 0: the driver starts it now
        rospy.loginfo("named_pose_server: to %s in %.2f s", name, duration)
        deadline = time.monotonic() + duration + self.settle_time
        while time.monotonic() < deadline and not rospy.is_shutdown():
            if self._robot_stop:  # the driver holds the arm: the move is over
                return self._robot_stop
            now = self._current()
            if now is not None and float(np.max(np.abs(now - goal))) <= self.tolerance:
                return MoveToNamedPoseResponse(
                    success=True, message=f"at {name} after a {duration:.2f} s move"
                )
            time.sleep(0.01)
        now = self._current()
        error = float(np.max(np.abs(now - goal))) if now is not None else float("nan")
        return self._refuse(f"did not reach {name}: largest joint error {error:.3f} rad")

    # --- controller switching (switching.py; README, Controller switching) ---
    def _switch_on(self) -> Switch | None:
        """Switches the trajectory controller on if a controller manager runs it stopped; the switch made.

        Raises:
            SwitchError: It cannot run (not loaded, or the switch was refused).
        """
        if not self._controller or not self._manager:
            return None
        if not _served(self._manager + "/list_controllers"):
            return None  # no controller manager (a driver without ros_control): nothing to switch
        try:
            listing = rospy.ServiceProxy(self._manager + "/list_controllers", ListControllers)()
        except (rospy.ServiceException, rospy.ROSException) as exc:
            raise SwitchError(f"{self._manager}/list_controllers failed: {exc}") from exc
        claims = {c.name: frozenset(r for claim in c.claimed_resources for r in claim.resources)
                  for c in listing.controller}
        switch = plan_switch(
            (Controller(c.name, c.state, claims[c.name]) for c in listing.controller), self._controller,
        )
        if switch is not None:
            result = self._switch(switch)
            if not result:
                raise SwitchError(f"could not switch {self._controller} on: {result.reason}")
        return switch

    def _switch(self, switch: Switch) -> _Switched:
        request = SwitchControllerRequest(
            start_controllers=list(switch.start), stop_controllers=list(switch.stop),
            strictness=SwitchControllerRequest.STRICT,
        )
        try:
            ok = rospy.ServiceProxy(self._manager + "/switch_controller", SwitchController)(request).ok
        except (rospy.ServiceException, rospy.ROSException) as exc:
            return _Switched(False, f"{self._manager}/switch_controller failed: {exc}")
        rospy.loginfo("named_pose_server: switch_controller start %s stop %s: %s",
                      list(switch.start), list(switch.stop), "ok" if ok else "refused")
        return _Switched(ok, "" if ok else f"switch_controller start {list(switch.start)} stop "
                         f"{list(switch.stop)} refused")


def _served(service: str) -> bool:
    """Whether the master knows `service`: asked, not waited for, so a move without that node pays nothing."""
    try:
        rosgraph.Master(rospy.get_name()).lookupService(service)
    except (rosgraph.MasterException, OSError):
        return False
    return True


class _Switched(NamedTuple):
    ok: bool
    reason: str

    def __bool__(self) -> bool:
        return self.ok


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
