"""Clock-jump detection, pure: compares the ROS clock with a monotonic clock between observations.

Under `use_sim_time` the ROS clock follows `/clock`, which jumps back when a simulator restarts or a bag
loops (`rosbag play --clock -l`) and forward when a bag is skipped ahead; on the wall clock an NTP step does
the same. Every duration a node measures across such a jump is wrong (a stale command looks fresh, a fresh
one stale), so a node halts, resets its timing and resumes with data stamped after the jump.
"""

from __future__ import annotations

import math

__all__ = ["ClockJump", "ClockWatch"]


class ClockJump:
    """One detected jump.

    Attributes:
        size: How far the ROS clock moved beyond what the monotonic clock did [s]: < 0 back, > 0 forward.
        at: The ROS time after the jump [s].
    """

    __slots__ = ("at", "size", "stopped")

    def __init__(self, size: float, at: float, stopped: bool = False) -> None:
        self.size = size
        self.at = at
        self.stopped = stopped

    @property
    def backwards(self) -> bool:
        return self.size < 0.0

    def describe(self) -> str:
        """In words, for a log line or a status message."""
        if self.stopped:
            return f"clock stopped at {self.at:.3f} s for {self.size:.3f} s (its source, e.g. /clock, died?)"
        way = "back" if self.backwards else "forward"
        return f"clock jumped {way} by {abs(self.size):.3f} s (to {self.at:.3f} s)"

    def __repr__(self) -> str:
        return f"ClockJump(size={self.size!r}, at={self.at!r}, stopped={self.stopped!r})"


class ClockWatch:
    """Watches one clock for jumps.

    Args:
        back_tolerance: A step back of more than this is a jump [s] (ROS time never runs back otherwise).
        forward_tolerance: The ROS clock advancing this much more than the monotonic clock is a jump [s].
            It must exceed what a faster-than-real-time simulation gains between two observations.
        stop_tolerance: The ROS clock standing still this long on the monotonic clock is reported once
            (a `ClockJump` with `stopped`), e.g. `/clock` from a simulator that died [s]; None: not watched.
    """

    def __init__(
        self,
        back_tolerance: float = 1e-3,
        forward_tolerance: float = 1.0,
        stop_tolerance: float | None = None,
    ) -> None:
        if not back_tolerance >= 0.0 or not forward_tolerance > 0.0:
            raise ValueError("clock jump tolerances must be >= 0 (back) and > 0 (forward)")
        self._back = back_tolerance
        self._forward = forward_tolerance
        self._last = math.nan
        self._last_mono = math.nan
        self._stop = stop_tolerance
        self._advanced = math.nan  # monotonic time of the last observation where the ROS clock moved
        self._stop_reported = False
        self.jumps = 0

    def observe(self, now: float, monotonic: float) -> ClockJump | None:
        """Records the ROS time `now` read at `monotonic` [s]; the jump since the last call, if any.

        Calls may come from several threads, so an observation older than the last one (a thread that read
        the clock before another but called later) is ignored by its monotonic stamp.
        """
        last, last_mono = self._last, self._last_mono
        if monotonic < last_mono:
            return None
        self._last, self._last_mono = now, monotonic
        if last != last or last == 0.0:  # first observation (NaN), or sim time before the first /clock
            self._advanced = monotonic
            return None
        step = now - last
        if step != 0.0:
            self._advanced = monotonic
            self._stop_reported = False
        elif self._stop is not None and not self._stop_reported and monotonic - self._advanced > self._stop:
            self._stop_reported = True
            return ClockJump(monotonic - self._advanced, now, stopped=True)
        if step < -self._back:
            self.jumps += 1
            return ClockJump(step, now)
        gain = step - (monotonic - last_mono)
        if gain > self._forward:
            self.jumps += 1
            return ClockJump(gain, now)
        return None

    def reset(self) -> None:
        """Forgets the last observation (e.g. after a pause the caller knows about)."""
        self._last = self._last_mono = self._advanced = math.nan
        self._stop_reported = False
