"""The sensor's real sample period, measured from the wrenches themselves.

Real sensors publish at their own rate (an arm's built-in sensor at 500 Hz, a model-based estimate at its
controller's publish rate, 30 Hz by default or 92 Hz in one recording, a separate F/T box at 125-7000 Hz),
which is rarely the `lp_filter_delta_t` somebody typed. A filter designed for the wrong period has the wrong
cutoff (the configured 5 Hz became 0.92 Hz on 92 Hz data), and a fixed stale timeout is either shorter than
one period of a slow sensor or far too long for a fast one (the package README has the numbers). The period
is the median of recent sample intervals, so single late or dropped samples do not move it; gaps longer than
`MAX_INTERVAL` (dropouts) are left out.
"""

from __future__ import annotations

import math

__all__ = ["MAX_INTERVAL", "SamplePeriod"]

MAX_INTERVAL = 0.5  # [s] an interval longer than this is a dropout, not the sensor's period


class SamplePeriod:
    """Median sample interval over windows of `window` samples; updated once per window (cheap per sample).

    Args:
        window: Intervals per estimate.
    """

    def __init__(self, window: int = 32) -> None:
        if window < 3:
            raise ValueError("window must hold at least 3 intervals")
        self._window = window
        self._intervals: list[float] = []
        self._last = math.nan
        self.period: float | None = None  # [s] the latest estimate; None until one window is full

    def add(self, t: float) -> bool:
        """Records a sample at time `t` [s] (its stamp, else its receive time); True when `period` changed."""
        last, self._last = self._last, t
        dt = t - last
        if not 0.0 < dt <= MAX_INTERVAL:  # the first sample (NaN), a repeat, a clock jump, a dropout
            return False
        intervals = self._intervals
        intervals.append(dt)
        if len(intervals) < self._window:
            return False
        intervals.sort()
        mid = len(intervals) // 2
        period = intervals[mid] if len(intervals) % 2 else 0.5 * (intervals[mid - 1] + intervals[mid])
        intervals.clear()
        changed = period != self.period
        self.period = period
        return changed

    def reset(self) -> None:
        """Forgets the last sample time (after a clock jump); keeps the estimate."""
        self._last = math.nan
        self._intervals.clear()
