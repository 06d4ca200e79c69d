"""Wait on conditions with deadlines (never fixed sleeps) and collect messages from topics."""

from __future__ import annotations

import threading
import time
from collections.abc import Callable

__all__ = ["Collector", "wait_until"]


def wait_until(predicate: Callable[[], bool], timeout: float = 10.0, message: str = "condition") -> None:
    """Polls `predicate` until it is true.

    Raises:
        AssertionError: not true within `timeout` seconds.
    """
    deadline = time.monotonic() + timeout
    while True:
        if predicate():
            return
        if time.monotonic() > deadline:
            raise AssertionError(f"timed out after {timeout} s waiting for {message}")
        time.sleep(0.01)


class Collector:
    """Subscribes to a topic and keeps every message with its receive time (time.monotonic)."""

    def __init__(self, topic: str, msg_class: type, queue_size: int = 1000) -> None:
        import rospy

        self.msgs: list = []
        self.times: list[float] = []
        self._lock = threading.Lock()
        self._sub = rospy.Subscriber(topic, msg_class, self._on_msg, queue_size=queue_size, tcp_nodelay=True)

    def _on_msg(self, msg: object) -> None:
        with self._lock:
            self.msgs.append(msg)
            self.times.append(time.monotonic())

    def wait_for(self, count: int = 1, timeout: float = 10.0) -> list:
        """Waits until at least `count` messages arrived; returns a copy of them."""
        wait_until(lambda: len(self.msgs) >= count, timeout, f"{count} messages on {self._sub.name}")
        with self._lock:
            return list(self.msgs)

    def wait_connected(self, timeout: float = 10.0) -> None:
        """Waits until a publisher is connected."""
        wait_until(lambda: self._sub.get_num_connections() > 0, timeout, f"a publisher on {self._sub.name}")

    def timed(self) -> list[tuple[float, object]]:
        """(receive time, message) of everything collected so far."""
        with self._lock:
            return list(zip(self.times, self.msgs, strict=True))

    def last(self):
        with self._lock:
            return self.msgs[-1] if self.msgs else None

    def clear(self) -> None:
        with self._lock:
            self.msgs.clear()
            self.times.clear()

    def close(self) -> None:
        self._sub.unregister()
