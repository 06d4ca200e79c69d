"""The one time-driven thread of a node: calls `tick()` when due, sleeping on the wall clock in between.

The node's pure core decides what is due and when (`tick` reads the ROS clock and returns its next due
time); sleeping on the wall clock means neither a clock jump nor a stopped `/clock` can stall the thread.
"""

from __future__ import annotations

import threading
import time
from collections.abc import Callable

import rospy

__all__ = ["start_ticker"]

MIN_SLEEP = 1e-4  # [s] a due time already past sleeps this long (no busy loop)


def start_ticker(tick: Callable[[], float], longest_sleep: float, name: str) -> threading.Thread:
    """Starts a daemon thread running `due = tick()` (ROS time [s]) until shutdown, sleeping until `due`
    but at most `longest_sleep` [s] (under sim time the clock's rate may differ from the wall clock's)."""

    def run() -> None:
        while not rospy.is_shutdown():
            due = tick()
            wait = due - rospy.get_time()
            time.sleep(min(max(wait, MIN_SLEEP), longest_sleep))

    thread = threading.Thread(target=run, name=name, daemon=True)
    thread.start()
    return thread
