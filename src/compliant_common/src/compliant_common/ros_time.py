"""rospy sleeps and timers that survive clock jumps (see clock.py for why they happen)."""

from __future__ import annotations

import time
from collections.abc import Callable
from typing import Any

import rospy

from compliant_common.clock import ClockJump, ClockWatch

__all__ = ["JumpAwareClock", "timer"]


def timer(period: float, callback: Callable[[Any], None]) -> rospy.Timer:
    """A `rospy.Timer` that restarts its schedule after a backward clock jump instead of dying."""
    return rospy.Timer(rospy.Duration(period), callback, reset=True)


class JumpAwareClock:
    """`rospy.get_time()` with jump detection: each reading is checked against the monotonic clock.

    Args:
        forward_tolerance, stop_tolerance: See `ClockWatch`.
    """

    def __init__(self, forward_tolerance: float = 1.0, stop_tolerance: float | None = None) -> None:
        self._watch = ClockWatch(forward_tolerance=forward_tolerance, stop_tolerance=stop_tolerance)

    def read(self) -> tuple[float, ClockJump | None]:
        """The ROS time [s], and the jump since the previous reading (by any thread) if there was one."""
        t = rospy.get_time()
        return t, self._watch.observe(t, time.monotonic())
