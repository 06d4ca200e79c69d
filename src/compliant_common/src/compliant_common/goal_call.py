"""One goal sent with actionlib's ActionClient and waited for (compliant_common README, the module table).

actionlib's SimpleActionClient stores the goal's handle only after `send_goal` returns; a status that
arrives in between (the server accepted the goal at once) reaches its transition callback first, which logs
"[ERROR] Got a transition callback on a goal handle that we're not tracking" and drops the transition: the
thesis demonstrations printed it on most runs. Here the callback waits for the handle under a lock.
"""

from __future__ import annotations

import threading
from collections.abc import Callable
from typing import Generic, TypeVar

import actionlib

__all__ = ["GoalCall"]

F = TypeVar("F")  # the action's feedback message
R = TypeVar("R")  # its result message


class GoalCall(Generic[F, R]):
    """Sends `goal` on `client` (an actionlib.ActionClient whose server is up); `feedback_cb(feedback)` gets
    each feedback message of this goal, `done_cb(result)` its result once (from actionlib's thread)."""

    def __init__(self, client: actionlib.ActionClient, goal: object,
                 feedback_cb: Callable[[F], None] | None = None,
                 done_cb: Callable[[R | None], None] | None = None) -> None:
        self._done = threading.Event()
        self._lock = threading.Lock()
        self._feedback_cb, self._done_cb = feedback_cb, done_cb
        with self._lock:  # callbacks wait here until the handle is known
            self.handle = client.send_goal(goal, transition_cb=self._on_transition,
                                           feedback_cb=self._on_feedback)

    def _on_transition(self, handle: actionlib.ClientGoalHandle) -> None:
        with self._lock:
            finished = handle == self.handle and handle.get_comm_state() == actionlib.CommState.DONE
            if not finished or self._done.is_set():
                return
            self._done.set()
        if self._done_cb is not None:
            self._done_cb(handle.get_result())

    def _on_feedback(self, handle: actionlib.ClientGoalHandle, feedback: F) -> None:
        with self._lock:
            ours = handle == self.handle
        if ours and self._feedback_cb is not None:
            self._feedback_cb(feedback)

    def wait(self, timeout: float | None = None) -> bool:
        """Whether the goal finished (a result came) within `timeout` wall seconds (None: no limit)."""
        return self._done.wait(timeout)

    def cancel(self) -> None:
        self.handle.cancel()

    def result(self) -> R | None:
        """The result message, None before the goal finished."""
        result: R | None = self.handle.get_result() if self._done.is_set() else None
        return result
