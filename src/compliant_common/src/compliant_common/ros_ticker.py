"""The one time-driven thread of a node: calls `tick()` when due, sleeping on the wall clock in between.

The node's pure core decides what is due and when (`tick` reads the ROS clock and returns its next due
time); sleeping on the wall clock means neither a clock jump nor a stopped `/clock` can stall the thread.
"""

from __future__ import annotations

import threading
import time
from collections.abc import Callable

import rospy

from compliant_common.rospy_internals import is_wallclock

__all__ = ["start_ticker"]

MIN_SLEEP = 1e-4  # [s] a due time already past sleeps this long (no busy loop)
# On the wall clock a sleep ends at the due time, but at most this many periods later (a clock jump seen by
# an input callback can make work due earlier than the thread planned).
WALL_SLEEP_PERIODS = 4.0


def start_ticker(tick: Callable[[], float], period: float, name: str) -> threading.Thread:
    """Starts a daemon thread running `due = tick()` (ROS time [s]) until shutdown, sleeping until `due`.

    `period` is the node's control period. On the wall clock a sleep lasts until `due` (at most
    WALL_SLEEP_PERIODS periods): a node that is due every period wakes every period, and a gap filler due
    2.5 periods after the last twist wakes between twists, not at a phase of its own that may fall on every
    wrench. Under simulated time the clock's rate may differ from the wall clock's, so a sleep lasts at most
    one period and the due time is checked again.
    """
    longest = period * (WALL_SLEEP_PERIODS if is_wallclock() else 1.0)

    def run() -> None:
        while not rospy.is_shutdown():
            due = tick()
            wait = due - rospy.get_time()
            time.sleep(min(max(wait, MIN_SLEEP), longest))

    thread = threading.Thread(target=run, name=name, daemon=True)
    thread.start()
    return thread
