"""Publish a message at a steady rate from a thread (a driver streaming its state, a teleop device)."""

from __future__ import annotations

import threading
from typing import Any

__all__ = ["Repeater"]


class Repeater:
    """Publishes `msg` on `pub` every 1/rate s until `stop()` (or until replaced by another `start`)."""

    def __init__(self, pub: Any) -> None:
        self.pub = pub
        self._stop = threading.Event()
        self._thread: threading.Thread | None = None

    def start(self, msg: Any, rate: float = 50.0) -> Repeater:
        self.stop()
        self._stop.clear()

        def loop() -> None:
            while not self._stop.is_set():
                self.pub.publish(msg)
                self._stop.wait(1.0 / rate)

        self._thread = threading.Thread(target=loop, daemon=True)
        self._thread.start()
        return self

    def stop(self) -> None:
        self._stop.set()
        if self._thread is not None:
            self._thread.join()
            self._thread = None
