"""ROS master loss and return: a dead master is seen within one poll (0.5 s), one that stops answering after
three unanswered polls (~4.5 s: a master merely slow on a loaded machine must not stop the arm); when it
answers again every registration of this process is restored.

rospy registers a node's topics, services and parameters once, at start; a roscore that restarts comes
back empty, and nobody finds the node again although its existing connections still carry data. This
watch polls the master (`getPid`, every `period` s, wall clock, short socket timeout) and, when it answers
again (or answers with a new pid: a restart between two polls), registers every publisher, subscriber and
service of this process again, connects the subscribers to the publishers the new master knows, and puts
back the parameters the node read at start (only those the new master lacks). Node-level reactions (stop
the arm while the graph is broken) go in `on_lost` / `on_back`.
"""

from __future__ import annotations

import http.client
import threading
import time
import xmlrpc.client
from collections.abc import Callable, Iterable
from typing import Any

import rosgraph
import rospy

from compliant_common.rospy_internals import node_uri, publisher_update, registrations

__all__ = ["MasterWatch"]

PROBE_TIMEOUT = 1.0  # [s] for the master to answer one poll
SLOW_POLLS = 3  # unanswered polls in a row that count as a lost master (a refused connection counts at once)


class _TimeoutTransport(xmlrpc.client.Transport):
    def __init__(self, timeout: float) -> None:
        super().__init__()
        self._timeout = timeout

    def make_connection(self, host: tuple[str, dict[str, str]] | str) -> http.client.HTTPConnection:
        conn = super().make_connection(host)
        conn.timeout = self._timeout
        return conn


class MasterWatch:
    """A daemon thread that watches the master of this rospy process (after `rospy.init_node`).

    Args:
        on_lost: Called once with the reason when the master stops answering.
        on_back: Called once the master answers again and every registration is restored.
        params: Parameter names (a namespace restores everything under it) to put back on a new master.
        period: Poll period [s] (wall clock).
    """

    def __init__(
        self,
        on_lost: Callable[[str], None],
        on_back: Callable[[], None],
        params: Iterable[str] = (),
        period: float = 0.5,
    ) -> None:
        self._on_lost = on_lost
        self._on_back = on_back
        self._period = period
        self._uri = rosgraph.get_master_uri()
        self._caller = rospy.get_caller_id()
        self._params: dict[str, Any] = {}
        for name in params:
            resolved = rospy.resolve_name(name)
            if rospy.has_param(resolved):
                self._params[resolved] = rospy.get_param(resolved)
        self._pid: int | None = None
        self.lost = False
        self.restorations = 0
        self._closed = False
        self._thread = threading.Thread(target=self._run, name="master_watch", daemon=True)
        self._thread.start()

    def close(self) -> None:
        self._closed = True

    def _proxy(self) -> Any:
        """The master's XML-RPC API (Any: its answers are untyped (code, message, value) triples)."""
        return xmlrpc.client.ServerProxy(self._uri, transport=_TimeoutTransport(PROBE_TIMEOUT))

    def _run(self) -> None:
        slow = 0  # polls in a row the master did not answer in time
        while not (self._closed or rospy.is_shutdown()):
            try:
                code, msg, pid = self._proxy().getPid(self._caller)
                if code != 1:
                    raise OSError(msg)
            except (OSError, xmlrpc.client.Error, http.client.HTTPException) as err:
                # Refused: nothing listens on the port, the master is gone. A timeout may be a master busy on
                # a loaded machine: only several in a row count, so a slow answer never stops a move.
                slow = 0 if isinstance(err, ConnectionRefusedError) else slow + 1
                if not self.lost and (slow == 0 or slow >= SLOW_POLLS):
                    self.lost = True
                    self._on_lost(f"ROS master {self._uri} unreachable ({err})")
            else:
                slow = 0
                if self.lost or (self._pid is not None and pid != self._pid):
                    if self._restore():
                        self.lost = False
                        self.restorations += 1
                        self._on_back()
                    else:
                        self.lost = True
                self._pid = pid
            time.sleep(self._period)

    def _restore(self) -> bool:
        """Registers everything of this process with the (new) master; False if it stopped answering."""
        master = self._proxy()
        caller, uri = self._caller, node_uri()
        try:
            for name, value in self._params.items():
                if not master.hasParam(caller, name)[2]:
                    master.setParam(caller, name, value)
            publications, subscriptions, services = registrations()
            for name, data_type in publications:
                master.registerPublisher(caller, name, data_type, uri)
            for name, data_type in subscriptions:
                code, _, publishers = master.registerSubscriber(caller, name, data_type, uri)
                if code == 1:
                    publisher_update(name, publishers)
            for name, service_uri in services:
                master.registerService(caller, name, service_uri, uri)
        except (OSError, xmlrpc.client.Error, http.client.HTTPException) as err:
            rospy.logwarn("master returned but registering again failed (%s); retrying", err)
            return False
        rospy.logwarn(
            "ROS master %s is back: registered again: %d publishers, %d subscribers, %d services, %d params",
            self._uri, len(publications),
            len(subscriptions), len(services), len(self._params),
        )
        return True
