"""The GUI's ROS side: service calls in worker threads, the status subscriber, a service watcher.

No Qt here: every result is handed to a callback from a non-UI thread, and the widget turns those
callbacks into Qt signals. rospy must be initialised (rospy.init_node, or rqt) before `start()`.
"""

from __future__ import annotations

import dataclasses
import threading
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from manipulator_control_gui.params import PARAMETERS, GuiSettings, load_settings

__all__ = ["Availability", "CallResult", "ContactControlClient", "RosNames"]


_NODE = GuiSettings.contact_control_node  # the declared default


@dataclass(frozen=True)
class RosNames:
    """Where contact_control is. Relative names resolve in the GUI node's namespace.

    The defaults are those of the parameter defaults (`manipulator_control_gui.params`).
    """

    configure_service: str = GuiSettings.configure_service
    tare_service: str = f"{_NODE}/tare"
    stop_service: str = f"{_NODE}/stop"
    reset_service: str = f"{_NODE}/reset"
    guide_service: str = f"{_NODE}/guide"
    status_topic: str = f"{_NODE}/status"
    recover_service: str = GuiSettings.recover_service
    teach_node: str = GuiSettings.teach_node
    task_server: str = GuiSettings.task_server
    #: compliant_control_msgs/ConfigureLaws, used instead of configure_service when registered (it answers
    #: with the reason of a refusal).
    laws_service: str = "configure_laws"

    @classmethod
    def from_settings(cls, settings: GuiSettings) -> RosNames:
        """The names from the panel's parameters: `contact_control_node` (namespace of the node's private
        names) and per-name overrides; `configure_laws_service` defaults to `configure_laws` beside
        `configure_service` (same namespace)."""
        node = settings.contact_control_node.rstrip("/")
        namespace, slash, _ = settings.configure_service.rpartition("/")
        return cls(
            configure_service=settings.configure_service,
            tare_service=settings.tare_service or f"{node}/tare",
            stop_service=settings.stop_service or f"{node}/stop",
            reset_service=settings.reset_service or f"{node}/reset",
            guide_service=settings.guide_service or f"{node}/guide",
            status_topic=settings.status_topic or f"{node}/status",
            recover_service=settings.recover_service,
            teach_node=settings.teach_node,
            task_server=settings.task_server,
            laws_service=settings.configure_laws_service or f"{namespace}{slash}{cls.laws_service}",
        )

    @classmethod
    def from_params(cls, get_param: Callable[[str, Any], Any]) -> RosNames:
        """Like :meth:`from_settings`, reading each name parameter with `get_param("~<key>", default)`.

        Raises:
            ValueError: A value of the wrong type, naming the key.
        """
        names = [key for key in PARAMETERS if key not in ("config", "retry_period")]
        return cls.from_settings(load_settings({key: get_param(f"~{key}", PARAMETERS[key].default)
                                                for key in names}))


@dataclass(frozen=True)
class CallResult:
    """How a service call went.

    Attributes:
        delivered: an answer arrived (False: the service was missing or the call failed in transport).
        success: the answer's `success`.
        code: an error code if the answer carried one (ConfigureLaws does; the ConfigureForceControl reply's
            error message has no field, so None there; None for Trigger services too).
        message: the Trigger or ConfigureLaws answer's message, or what went wrong in transport.
    """

    delivered: bool
    success: bool = False
    code: int | None = None
    message: str = ""


@dataclass(frozen=True)
class Availability:
    """Result of one look at the master: `master` reachable, the services not registered, and whether the
    optional ConfigureLaws service is."""

    master: bool
    missing: tuple[str, ...]
    laws: bool = False

    @property
    def ok(self) -> bool:
        return self.master and not self.missing


class ContactControlClient:
    """Calls contact_control's services off the caller's thread and follows its status topic.

    Args:
        names: service and topic names.
        on_status: called (from a rospy thread) with each ContactControlStatus.
        on_availability: called (from the watcher thread) when the services appear or disappear.
        retry_period: seconds between looks at the master.
    """

    def __init__(
        self,
        names: RosNames,
        on_status: Callable[[Any], None],
        on_availability: Callable[[Availability], None],
        retry_period: float = 1.0,
    ) -> None:
        import rospy

        self._rospy = rospy
        self.names = names
        fields = dataclasses.fields(names)
        self.resolved = RosNames(**{f.name: rospy.resolve_name(getattr(names, f.name)) for f in fields})
        self._on_status = on_status
        self._on_availability = on_availability
        self._retry_period = retry_period
        self._stop = threading.Event()
        self._watcher: threading.Thread | None = None
        self._sub = None
        self._last: Availability | None = None
        self._replay_client: Any = None
        self._task_subs: list[Any] = []
        self._task_cancel: Any = None

    def start(self) -> None:
        """Subscribes to the status and starts watching the services."""
        from compliant_control_msgs.msg import ContactControlStatus

        self._sub = self._rospy.Subscriber(
            self.resolved.status_topic, ContactControlStatus, self._on_status, queue_size=1
        )
        self._watcher = threading.Thread(target=self._watch, name="mcg-service-watcher", daemon=True)
        self._watcher.start()

    def follow_tasks(self, on_goal: Callable[[Any], None], on_feedback: Callable[[Any], None],
                     on_result: Callable[[Any], None]) -> None:
        """Follows task_server's `~execute` action as any client may (its goal, feedback and result
        topics), whoever sent the goal; the callbacks get the messages' goal, feedback and result from rospy
        threads."""
        from actionlib_msgs.msg import GoalID
        from compliant_control_msgs.msg import (
            ExecuteTaskActionFeedback,
            ExecuteTaskActionGoal,
            ExecuteTaskActionResult,
        )

        action = self.resolved.task_server + "/execute"
        # Made now, so it is connected to task_server long before someone presses Cancel.
        self._task_cancel = self._rospy.Publisher(f"{action}/cancel", GoalID, queue_size=1)
        self._task_subs = [
            self._rospy.Subscriber(f"{action}/goal", ExecuteTaskActionGoal, lambda m: on_goal(m.goal),
                                   queue_size=5),
            self._rospy.Subscriber(f"{action}/feedback", ExecuteTaskActionFeedback,
                                   lambda m: on_feedback(m.feedback), queue_size=1),
            self._rospy.Subscriber(f"{action}/result", ExecuteTaskActionResult, lambda m: on_result(m.result),
                                   queue_size=5),
        ]

    def cancel_task(self) -> None:
        """Cancels every goal of task_server's `~execute` (actionlib: an empty GoalID on `cancel`), the one a
        command line or another program started included."""
        from actionlib_msgs.msg import GoalID

        if self._task_cancel is not None:
            self._task_cancel.publish(GoalID())

    def shutdown(self) -> None:
        """Stops the watcher and unsubscribes; calls in flight finish on their own."""
        self._stop.set()
        if self._sub is not None:
            self._sub.unregister()
            self._sub = None
        for sub in self._task_subs:
            sub.unregister()
        self._task_subs = []
        if self._task_cancel is not None:
            self._task_cancel.unregister()
        if self._watcher is not None:
            self._watcher.join(timeout=2.0)

    def check_availability(self) -> Availability:
        """Asks the master which of the services are registered (blocking; a watcher-thread call)."""
        import rosgraph

        master = rosgraph.Master(self._rospy.get_name())
        missing = []
        try:
            for name in (
                self.resolved.configure_service,
                self.resolved.stop_service,
                self.resolved.tare_service,
                self.resolved.reset_service,
            ):
                try:
                    master.lookupService(name)
                except rosgraph.MasterError:
                    missing.append(name)
            try:
                master.lookupService(self.resolved.laws_service)
                laws = True
            except rosgraph.MasterError:
                laws = False  # an older contact_control: the original service alone
        except OSError:
            return Availability(False, ())
        return Availability(True, tuple(missing), laws)

    def _watch(self) -> None:
        while not self._stop.is_set():
            availability = self.check_availability()
            if availability != self._last:
                self._last = availability
                self._on_availability(availability)
            self._stop.wait(self._retry_period)

    def configure(self, request: Any, on_done: Callable[[CallResult], None]) -> None:
        """Sends `request` to the non-blocking configure service; `on_done` gets the result.

        It runs in a worker thread, never the caller's (UI) thread: a hung service cannot freeze the window.
        """
        from cartesian_impedance_msgs.srv import ConfigureForceControl

        def answer(response: Any) -> CallResult:
            # CartesianForceCtrlErrorCodes declares constants only: a code can only come from a future field.
            code = getattr(response.error, "val", None)
            return CallResult(True, bool(response.success), None if code is None else int(code))

        self._call(self.resolved.configure_service, ConfigureForceControl, request, answer, on_done)

    def configure_laws(self, request: Any, on_done: Callable[[CallResult], None]) -> None:
        """Sends a ConfigureLaws `request` in a worker thread; the result carries its code and message."""
        from compliant_control_msgs.srv import ConfigureLaws

        def answer(response: Any) -> CallResult:
            return CallResult(True, bool(response.success), int(response.code), str(response.message))

        self._call(self.resolved.laws_service, ConfigureLaws, request, answer, on_done)

    def trigger(self, which: str, on_done: Callable[[CallResult], None]) -> None:
        """Calls the std_srvs/Trigger service `which` ('stop', 'tare', 'reset' or 'recover') in a worker
        thread."""
        from std_srvs.srv import Trigger, TriggerRequest

        name = {
            "stop": self.resolved.stop_service,
            "tare": self.resolved.tare_service,
            "reset": self.resolved.reset_service,
            "recover": self.resolved.recover_service,
        }[which]

        def answer(response: Any) -> CallResult:
            return CallResult(True, bool(response.success), None, str(response.message))

        self._call(name, Trigger, TriggerRequest(), answer, on_done)

    def guide(self, enable: bool, on_done: Callable[[CallResult], None]) -> None:
        """Switches hand-guiding on (the node's guide_axes) or off in a worker thread; the result carries the
        node's answer (what runs now, or why not)."""
        from compliant_control_msgs.srv import Guide, GuideRequest

        def answer(response: Any) -> CallResult:
            return CallResult(True, bool(response.success), int(response.code), str(response.message))

        self._call(self.resolved.guide_service, Guide, GuideRequest(enable=enable), answer, on_done)

    # --- teach (program_server) ---
    def record(self, name: str, on_done: Callable[[CallResult], None]) -> None:
        """Starts recording program `name` (teach's ~record) in a worker thread."""
        from compliant_control_msgs.srv import RecordProgram, RecordProgramRequest

        def answer(response: Any) -> CallResult:
            return CallResult(True, bool(response.success), None, str(response.message))

        request = RecordProgramRequest(name=name)
        self._call(self.resolved.teach_node + "/record", RecordProgram, request, answer, on_done)

    def stop_recording(self, on_done: Callable[[CallResult], None]) -> None:
        """Stops and saves the recording (teach's ~stop)."""
        from std_srvs.srv import Trigger, TriggerRequest

        def answer(response: Any) -> CallResult:
            return CallResult(True, bool(response.success), None, str(response.message))

        self._call(self.resolved.teach_node + "/stop", Trigger, TriggerRequest(), answer, on_done)

    def replay(self, name: str, speed: float, press_axis: str, press_force: float,
               on_done: Callable[[CallResult], None]) -> None:
        """Sends a replay goal (teach's ~replay action); `on_done` gets its result when it ends."""
        import actionlib
        from compliant_common.goal_call import GoalCall
        from compliant_control_msgs.msg import ReplayProgramAction, ReplayProgramGoal

        rospy = self._rospy

        def run() -> None:
            client = self._replay_client
            if client is None:
                client = self._replay_client = actionlib.ActionClient(
                    self.resolved.teach_node + "/replay", ReplayProgramAction)
            if not client.wait_for_server(rospy.Duration(2.0)):
                where = self.resolved.teach_node + "/replay"
                on_done(CallResult(False, message=f"{where} is not available (is program_server running?)"))
                return

            def done(result: Any) -> None:
                if result is None:
                    on_done(CallResult(False, message="the replay ended without a result"))
                else:
                    on_done(CallResult(True, bool(result.success), None, str(result.message)))

            GoalCall(client, ReplayProgramGoal(name=name, speed=speed, press_axis=press_axis,
                                               press_force=press_force), done_cb=done)

        threading.Thread(target=run, name="mcg-replay", daemon=True).start()

    def cancel_replay(self) -> None:
        """Cancels the replay this panel started (its result then says where it stopped)."""
        if self._replay_client is not None:
            self._replay_client.cancel_all_goals()

    def _call(
        self,
        name: str,
        service_class: type,
        request: Any,
        answer: Callable[[Any], CallResult],
        on_done: Callable[[CallResult], None],
    ) -> None:
        rospy = self._rospy

        def run() -> None:
            proxy = rospy.ServiceProxy(name, service_class)
            try:
                result = answer(proxy.call(request))
            except rospy.ServiceException as err:
                text = str(err)
                if "unavailable" in text or "does not exist" in text:
                    text = f"service {name} is not available (is contact_control_node running?)"
                result = CallResult(False, message=text)
            except (rospy.ROSException, OSError) as err:
                result = CallResult(False, message=f"calling {name} failed: {err}")
            finally:
                proxy.close()
            on_done(result)

        threading.Thread(target=run, name=f"mcg-call{name.replace('/', '-')}", daemon=True).start()
