"""Real-time pacing of the simulation loop and measurement of the real-time factor (no ROS, no sleeping).

The loop asks :meth:`Pacer.wait_time` how long to sleep before the next step is due and calls
:meth:`Pacer.step_done` after each step; :meth:`Pacer.lag` tells it when it is catching up (the node then
skips publishing the intermediate states). Steps are scheduled on a fixed wall-clock grid (one step every
``dt / real_time_factor`` seconds), so a late step is followed by the next ones at once, without sleeping,
until the simulation has caught up; a backlog longer than ``max_lag`` is dropped instead (the simulation
then runs behind the wall clock for good, and :attr:`Pacer.dropped` counts the lost time). Without
``catch_up`` (simulated time: nothing waits on the wall clock) a late step restarts the grid: the simulation
slows down instead of stepping ahead unpublished.
"""

from __future__ import annotations

import math

__all__ = ["Pacer", "RtfMeter", "TrailingPublication"]


class Pacer:
    """Fixed-grid scheduler: step ``k`` is due at ``start + k * dt / real_time_factor`` (wall clock).

    Args:
        dt: Simulation timestep [s].
        real_time_factor: Simulated seconds per wall-clock second; 0 runs as fast as possible.
        max_lag: Largest backlog [s of wall time] caught up by stepping without sleeping; more is dropped.
        catch_up: False: no backlog is kept (a late step is due now, the next a period later).

    Raises:
        ValueError: On a non-positive ``dt`` or ``max_lag``, or a negative or non-finite factor.
    """

    def __init__(self, dt: float, real_time_factor: float = 1.0, max_lag: float = 0.1,
                 catch_up: bool = True) -> None:
        if not (math.isfinite(dt) and dt > 0.0):
            raise ValueError(f"dt must be > 0, got {dt}")
        if not (math.isfinite(real_time_factor) and real_time_factor >= 0.0):
            raise ValueError(f"real_time_factor must be >= 0 (0: fastest), got {real_time_factor}")
        if not (math.isfinite(max_lag) and max_lag > 0.0):
            raise ValueError(f"max_lag must be > 0, got {max_lag}")
        self.period = dt / real_time_factor if real_time_factor > 0.0 else 0.0
        self.max_lag = max_lag
        self.catch_up = catch_up
        self.dropped = 0.0  # wall time given up to the backlog limit [s]
        self._next = math.nan

    def start(self, now: float) -> None:
        """Make the first step due at ``now`` (wall clock [s], e.g. time.monotonic())."""
        self._next = now

    def wait_time(self, now: float) -> float:
        """Seconds until the next step is due (0: step now). Drops a backlog longer than ``max_lag``."""
        if math.isnan(self._next):
            self.start(now)
        if self.period == 0.0:
            return 0.0
        ahead = self._next - now
        if ahead < 0.0 and not self.catch_up:
            self._next = now
            return 0.0
        if ahead < -self.max_lag:
            self.dropped -= ahead
            self._next = now
            return 0.0
        return max(ahead, 0.0)

    def lag(self, now: float) -> float:
        """How far the next step is overdue [s] (0 when on time, ahead, running as fast as possible, or
        without catch-up: nothing is ever owed then)."""
        if self.period == 0.0 or not self.catch_up or math.isnan(self._next):
            return 0.0
        return max(now - self._next, 0.0)

    def step_done(self) -> None:
        """One step was taken: the next one is due one period later on the grid."""
        self._next += self.period


class RtfMeter:
    """Real-time factor over successive windows: simulated time advanced / wall time elapsed.

    Args:
        period: Window length [s of wall time].
    """

    def __init__(self, period: float = 2.0) -> None:
        if not (math.isfinite(period) and period > 0.0):
            raise ValueError(f"period must be > 0, got {period}")
        self.period = period
        self.value = math.nan  # factor of the last completed window
        self._wall0 = math.nan
        self._sim0 = 0.0

    def update(self, wall: float, sim_time: float) -> bool:
        """Record the clocks now; returns True when a window completed (then :attr:`value` is new).

        A simulated clock that went backwards (a reset) restarts the window.
        """
        if math.isnan(self._wall0) or sim_time < self._sim0:
            self._wall0, self._sim0 = wall, sim_time
            return False
        elapsed = wall - self._wall0
        if elapsed < self.period:
            return False
        self.value = (sim_time - self._sim0) / elapsed
        self._wall0, self._sim0 = wall, sim_time
        return True


class TrailingPublication:
    """When a publication that trails another goes out: the joint states, `delay` after the wrench of the same
    state, or before the next step that reads a new state, whichever comes first.

    Args:
        delay: Wall-clock delay [s]; 0 publishes at once (:meth:`armed` then answers False).
    """

    def __init__(self, delay: float) -> None:
        if not (math.isfinite(delay) and delay >= 0.0):
            raise ValueError(f"delay must be >= 0, got {delay}")
        self.delay = delay
        self._due: float | None = None

    def armed(self, now: float) -> bool:
        """The leading publication went out at `now`: True if the trailing one is now pending, False if it is
        to go out at once."""
        if self.delay == 0.0:
            return False
        self._due = now + self.delay
        return True

    def due(self, now: float, state_changes: bool = False) -> bool:
        """Whether the pending publication goes out now (then it is no longer pending): its time has come, or
        the next step (`state_changes`) would overwrite what it publishes."""
        if self._due is None or not (state_changes or now >= self._due):
            return False
        self._due = None
        return True

    def sleep_time(self, now: float, wait: float) -> float:
        """How long to sleep when the next step is `wait` away: no later than the pending publication."""
        return wait if self._due is None else max(min(wait, self._due - now), 0.0)
