"""rospy sleeps and timers that survive clock jumps (see clock.py for why they happen)."""

from __future__ import annotations

import threading
import time
from collections.abc import Callable
from typing import TypeAlias

import rospy

from compliant_common.clock import ClockJump, ClockWatch
from compliant_common.rospy_internals import is_wallclock

__all__ = ["JumpAwareClock", "MonotonicTimer", "TimerCallback", "TimerEvent", "timer"]

#: rospy's timer event (public rospy.timer API; named here once for annotations).
TimerEvent: TypeAlias = rospy.timer.TimerEvent

#: A timer's callback: gets rospy's `TimerEvent`, or None from a `MonotonicTimer`.
TimerCallback: TypeAlias = Callable[[TimerEvent | None], None]

#: [s] A reading whose ROS clock read is further than this from its monotonic stamp is not judged.
PAIR_TOLERANCE = 2e-4


class MonotonicTimer:
    """A periodic callback on the monotonic clock, in a daemon thread: `rospy.Timer`'s contract (a `shutdown`
    method; the schedule restarts after falling more than two periods behind, no burst of missed calls) at
    a fraction of its per-cycle work (rospy's does about ten `rospy.Time` operations per tick), and immune to
    wall-clock steps (NTP), which rospy's wall-clock timer follows. Used by `timer` on the wall clock.

    Args:
        period: [s].
        callback: Called with None (rospy's `TimerEvent` costs more than the callbacks of this stack use).
        name: Of the thread.
    """

    def __init__(self, period: float, callback: TimerCallback, name: str = "timer") -> None:
        if not period > 0.0:
            raise ValueError(f"timer period must be > 0, got {period}")
        self._period = period
        self._callback = callback
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._run, name=name, daemon=True)
        self._thread.start()

    def _run(self) -> None:
        period, callback, stopped = self._period, self._callback, self._stop.is_set
        due = time.monotonic()
        while not (stopped() or rospy.is_shutdown()):
            due += period
            pause = due - time.monotonic()
            if pause > 0.0:
                time.sleep(pause)
            elif pause < -2.0 * period:  # far behind (a stall): start a new schedule instead of a burst
                due = time.monotonic()
            if stopped():
                break
            callback(None)

    def shutdown(self) -> None:
        """No call starts after this returns (one in progress finishes)."""
        self._stop.set()


def timer(period: float, callback: TimerCallback) -> rospy.Timer | MonotonicTimer:
    """A periodic callback that survives clock jumps: on the wall clock a `MonotonicTimer` (callback gets
    None); under simulated time a `rospy.Timer` on the ROS clock that restarts its schedule after a backward
    jump instead of dying (callback gets its `TimerEvent`). Either has `shutdown()`."""
    if is_wallclock():
        return MonotonicTimer(period, callback)
    return rospy.Timer(rospy.Duration(period), callback, reset=True)


class JumpAwareClock:
    """`rospy.get_time()` with jump detection: each reading is checked against the monotonic clock.

    Args:
        forward_tolerance, stop_tolerance: See `ClockWatch`.
    """

    def __init__(self, forward_tolerance: float = 1.0, stop_tolerance: float | None = None) -> None:
        self._watch = ClockWatch(forward_tolerance=forward_tolerance, stop_tolerance=stop_tolerance)
        self._observe = self._watch.observe

    def read(self) -> tuple[float, ClockJump | None]:
        """The ROS time [s], and the jump since the previous reading (by any thread) if there was one.

        The two clocks are read one after the other; a thread held up between them (preempted, or the GIL
        passed to another thread that read the clock meanwhile) would pair an old ROS time with a late
        monotonic stamp, which looked like the clock stepping back by the delay (1-4 ms on a loaded machine:
        jog_arm then halted "until a fresh joint state"). Such a reading (its monotonic reads more than
        `PAIR_TOLERANCE` apart) is returned unjudged; the next one is.
        """
        before = time.monotonic()
        # rospy.get_time() on the wall clock builds a rospy.Time first (1.9 us, time.time() 0.1 us); this is
        # read several times per control cycle.
        t = time.time() if is_wallclock() else rospy.get_time()
        after = time.monotonic()
        if after - before > PAIR_TOLERANCE:
            return t, None
        return t, self._observe(t, before)
