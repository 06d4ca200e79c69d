"""Wrench-to-command latency as the driver sees it (no ROS): for each wrench the driver publishes, the time
until the next joint command arrives.

A joint command carries nothing that names the wrench it answers, so each wrench is paired with the first
command after it. When the stack answers every wrench within a period this is its exact latency; a late
answer is counted against every wrench it was late for, so the figure errs high, never low. Wrenches that
get no command within `horizon` (nothing is controlling the arm) are dropped, not counted.

Thread use: `wrench_sent` from the stepping loop, `command_received` from a subscriber thread, `take` from
either; deque appends and pops are atomic, so no lock is needed.
"""

from __future__ import annotations

import collections

__all__ = ["LatencyProbe"]


class LatencyProbe:
    """Pairs published wrenches with the joint commands that follow them.

    Args:
        horizon: Longest wait [s] still taken as an answer; older unanswered wrenches are dropped.
        capacity: Most samples kept between two `take` calls (the oldest go first).

    Raises:
        ValueError: On a non-positive horizon or capacity.
    """

    def __init__(self, horizon: float, capacity: int = 8192) -> None:
        if not horizon > 0.0 or capacity < 1:
            raise ValueError(f"horizon and capacity must be > 0, got {horizon}, {capacity}")
        self.horizon = horizon
        self._pending: collections.deque[float] = collections.deque()
        self._samples: collections.deque[tuple[float, float]] = collections.deque(maxlen=capacity)

    def wrench_sent(self, t: float) -> None:
        """A wrench is being published at `t` (monotonic clock [s])."""
        pending = self._pending
        pending.append(t)
        # A command arriving in another thread may empty the deque between the test and the pop.
        try:
            while pending[0] < t - self.horizon:
                pending.popleft()
        except IndexError:
            pass

    def command_received(self, t: float, wall: float) -> None:
        """A joint command arrived at `t` (same clock as `wrench_sent`), `wall` being time.time() then."""
        pending, samples = self._pending, self._samples
        while pending:
            sent = pending.popleft()
            if t - sent <= self.horizon:
                samples.append((wall, t - sent))

    def take(self) -> list[float]:
        """The samples since the last call as flat `[wall_0, latency_0, wall_1, latency_1, ...]` [s]."""
        out: list[float] = []
        samples = self._samples
        while samples:
            out.extend(samples.popleft())
        return out
