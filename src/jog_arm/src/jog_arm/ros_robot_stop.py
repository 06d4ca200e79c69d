"""The ROS side of the robot's own stops (`jog_arm.robot_stop`; the README's *Robot stops*).

Subscribes to the driver topics the ``robot_stop`` parameter names, hands their values to the stage under
the node's lock (a stop holds the arm in the same callback, before the next cycle), latches the reason on
``~robot_stop`` (std_msgs/String, "" while the robot runs) and serves ``~recover`` (std_srvs/Trigger): the
driver's recovery steps in order (Trigger services, actions with an empty goal), then, once the driver
reports running, commands move the arm again from the measured joints. The answer says what failed.
"""

from __future__ import annotations

import functools
import threading
import time
from typing import Any

import roslib.message
import rospy
from std_msgs.msg import String
from std_srvs.srv import Trigger, TriggerRequest, TriggerResponse

from jog_arm.robot_stop import RecoveryStep, RobotStop, StopWatch, parse_robot_stop
from jog_arm.settings import SettingsError
from jog_arm.stage import JogStage

__all__ = ["RobotStopRos"]

RECOVER_WAIT = 5.0  # [s] for the driver to report running after its recovery services answered
SERVICE_WAIT = 2.0  # [s] for a recovery service or action server to appear
ACTION_WAIT = 10.0  # [s] for a recovery action's result


def _constant_names(cls: type) -> dict[Any, str]:
    """A message class's constants by value ({3: 'PROTECTIVE_STOP', ...}); the first name wins."""
    names: dict[Any, str] = {}
    for name in dir(cls):
        value = getattr(cls, name)
        if name.isupper() and isinstance(value, int | str) and not isinstance(value, bool):
            names.setdefault(value, name)
    return names


class RobotStopRos:
    """Watches the driver and serves ``~recover`` (every stage call under ``lock``).

    Raises:
        SettingsError: The ``robot_stop`` parameter is invalid or names a message type that is not installed.
    """

    def __init__(self, stage: JogStage, lock: threading.Lock, private_ns: str, prefix: str) -> None:
        self._stage, self._lock = stage, lock
        watches, self._steps = parse_robot_stop(rospy.get_param(private_ns + "robot_stop", {}), prefix)
        for step in self._steps:  # refused at start-up, not when a stop needs it
            if step.action_type:
                self._message_type(step.action_type, f"{prefix}robot_stop: action {step.name}")
        self.robot = RobotStop(watches)
        self._changed = threading.Condition()
        classes = [self._message_class(w, prefix) for w in watches]
        self._names = [_constant_names(cls) for cls in classes]
        self._pub = rospy.Publisher(private_ns + "robot_stop", String, queue_size=1, latch=True)
        self._pub.publish(String(""))
        self._subs = [rospy.Subscriber(w.topic, classes[i], functools.partial(self._on_state, i),
                                       queue_size=1, tcp_nodelay=True) for i, w in enumerate(watches)]
        self._service = rospy.Service(private_ns + "recover", Trigger, self._on_recover)
        if watches:
            rospy.loginfo("jog_arm_server: watching the robot's own stops on %s; recovery: %s",
                          [rospy.resolve_name(w.topic) for w in watches],
                          [rospy.resolve_name(step.name) for step in self._steps] or "none")

    @staticmethod
    def _message_class(watch: StopWatch, prefix: str) -> type:
        cls = RobotStopRos._message_type(watch.type, f"{prefix}robot_stop: {watch.topic}")
        fields = list(getattr(cls, "__slots__", ()))
        if watch.field.split(".")[0] not in fields:
            raise SettingsError(f"{prefix}robot_stop: {watch.type} has no field {watch.field!r} "
                                f"(fields: {fields})")
        return cls

    def _on_state(self, index: int, msg: Any) -> None:
        value = functools.reduce(getattr, self.robot.watches[index].field.split("."), msg)
        with self._lock:
            was = self.robot.reason
            if self.robot.update(index, value, self._names[index].get(value, "")):
                self._stage.robot_stopped(self.robot.reason)
            elif was and not self.robot.reason:  # stopped before the robot ever ran: cleared by itself
                self._stage.robot_recovered()
            reason = self.robot.reason
        if reason != was:
            self._pub.publish(String(reason))
        with self._changed:
            self._changed.notify_all()

    def _on_recover(self, _req: TriggerRequest) -> TriggerResponse:
        with self._lock:
            reason = self.robot.reason
        if not reason:
            return TriggerResponse(success=True, message="the robot was not stopped: nothing to recover")
        for step in self._steps:
            answer = self._call(step)
            if answer is not None:
                return TriggerResponse(success=False, message=f"{answer}; still stopped: {reason}")
        deadline = time.monotonic() + RECOVER_WAIT
        with self._changed:
            while not self.robot.driver_running() and time.monotonic() < deadline:
                self._changed.wait(deadline - time.monotonic())
        with self._lock:
            ok, message = self.robot.recover()
            if ok:
                self._stage.robot_recovered()
        if ok:
            self._pub.publish(String(""))
            message += "; commands move the arm again, from the measured joints"
            rospy.loginfo("jog_arm_server: %s", message)
        return TriggerResponse(success=ok, message=message)

    @staticmethod
    def _call(step: RecoveryStep) -> str | None:
        """Run one recovery step: None if it succeeded, else why not."""
        name = rospy.resolve_name(step.name)
        if step.action_type:
            return _run_action(name, RobotStopRos._message_type(step.action_type, name))
        try:
            rospy.wait_for_service(name, timeout=SERVICE_WAIT)
            answer = rospy.ServiceProxy(name, Trigger)()
        except (rospy.ROSException, rospy.ServiceException) as err:
            return f"{name} failed: {err}"
        if not answer.success:
            return f"{name} refused: {answer.message}"
        return None

    @staticmethod
    def _message_type(type_name: str, where: str) -> type:
        cls: type | None = roslib.message.get_message_class(type_name)
        if cls is None:
            raise SettingsError(f"{where}: message type {type_name!r} is not installed")
        return cls

    def shutdown(self) -> None:
        self._service.shutdown()
        for sub in self._subs:
            sub.unregister()
        self._pub.unregister()


def _run_action(name: str, action: type) -> str | None:
    """An action with an empty goal (an error recovery): None if it succeeded, else why not."""
    import actionlib
    from actionlib_msgs.msg import GoalStatus

    client = actionlib.SimpleActionClient(name, action)
    try:
        if not client.wait_for_server(rospy.Duration(SERVICE_WAIT)):
            return f"{name}: no action server within {SERVICE_WAIT:g} s"
        goal_class = type(action().action_goal.goal)
        client.send_goal(goal_class())
        if not client.wait_for_result(rospy.Duration(ACTION_WAIT)):
            client.cancel_goal()
            return f"{name}: no result within {ACTION_WAIT:g} s"
        state = client.get_state()
        if state != GoalStatus.SUCCEEDED:
            return f"{name} did not succeed (goal status {state}: {client.get_goal_status_text()})"
        return None
    finally:
        client.stop_tracking_goal()
