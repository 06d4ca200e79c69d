"""Control-cycle timing: how many cycles ran, how many were missed, and how regular they were."""

from __future__ import annotations

import collections
import statistics

__all__ = ["FILL_AFTER", "CycleMonitor", "next_fill_time"]


# publish_on_command: twists run the cycles; a gap filler runs one this many periods after the last
# twist-driven cycle, then one per period until twists return (halting). Above 2, so a late or single
# missing twist never gets a duplicate, older command (the driver holds a velocity for 3 periods); the half
# period puts its wake-ups between twists.
FILL_AFTER = 2.5


def next_fill_time(last_twist_cycle: float, last_fill_cycle: float, period: float) -> float:
    """publish_on_command: when the gap filler runs its next cycle [s], given the last cycle a twist ran and
    the last one it ran itself."""
    return max(last_twist_cycle + FILL_AFTER * period, last_fill_cycle + period)


class CycleMonitor:
    """Counts cycles from their start times; a gap of n periods (rounded) means n - 1 missed cycles.

    Args:
        period: Nominal period [s].
        keep: How many recent period errors to keep for the percentiles.
    """

    def __init__(self, period: float, keep: int = 100_000) -> None:
        self.period = float(period)
        self._errors: collections.deque[float] = collections.deque(maxlen=keep)
        self.total = 0  # cycles since start (not reset with the window)
        self.reset()

    def reset(self) -> None:
        """Starts a new measurement window (the next tick only sets the reference time)."""
        self._last: float | None = None
        self.cycles = 0
        self.missed = 0
        self.max_gap = 0.0
        self._errors.clear()

    def tick(self, now: float) -> int:
        """Records a cycle starting at `now` [s]; returns how many cycles were missed just before it."""
        self.cycles += 1
        self.total += 1
        last, self._last = self._last, now
        if last is None:
            return 0
        gap = now - last
        self.max_gap = max(self.max_gap, gap)
        self._errors.append(abs(gap - self.period))
        missed = max(0, round(gap / self.period) - 1)
        self.missed += missed
        return missed

    def summary(self) -> dict[str, float]:
        """cycles, missed, max_gap_ms and the period error p50/p99 [us] of the window."""
        errors = sorted(self._errors)
        p50 = statistics.median(errors) * 1e6 if errors else 0.0
        p99 = errors[min(len(errors) - 1, int(0.99 * len(errors)))] * 1e6 if errors else 0.0
        return {
            "cycles": self.cycles,
            "missed": self.missed,
            "period_error_p50_us": round(p50, 1),
            "period_error_p99_us": round(p99, 1),
            "max_gap_ms": round(self.max_gap * 1e3, 3),
        }
