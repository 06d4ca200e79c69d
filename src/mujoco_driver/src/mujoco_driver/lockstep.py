"""Lockstep with the stack: the simulation waits for a late controller instead of driving on (no ROS).

A real arm goes on moving while its controller is descheduled, until the driver's receive timeout; a
simulated one on a busy machine would do the same for as long as the stall lasts (0.1-0.3 s on a shared
2-core machine), and a test would then judge the machine's load instead of the controller. So while the arm
is driven (the newest velocity command is not zero) the loop steps at most `lead` seconds of simulated time
past

* the newest velocity command, and
* with an echo topic, the newest published state the controller has answered (a message stamped with the
  stamp of the wrench it processed: contact_control's ``~contact_wrench`` when jog_arm runs apart),

and then waits for them. A stack silent for `wait` wall seconds is given up on until it speaks again: the
simulation then runs on and the velocity watchdog (``command_timeout``) stops the arm, as before.

Thread use: ``command``, ``echo`` and ``waits`` from subscriber threads and the loop; one condition guards
the state, and `hold` (the loop's per-step check) reads plain attributes without it.
"""

from __future__ import annotations

import collections
import math
import threading

__all__ = ["Lockstep"]


class Lockstep:
    """When the stepping loop must wait for the stack, and the waiting itself.

    Args:
        lead: Simulated time [s] the simulation may run past the stack's newest answer (> 0).
        history: Published states remembered to place an echo's stamp in simulated time.

    Raises:
        ValueError: On a non-positive `lead` or `history`.
    """

    def __init__(self, lead: float, history: int = 512) -> None:
        if not (math.isfinite(lead) and lead > 0.0) or history < 1:
            raise ValueError(f"lead and history must be > 0, got {lead}, {history}")
        self.lead = lead
        self._cond = threading.Condition()
        self._published: collections.deque[tuple[int, float]] = collections.deque(maxlen=history)
        self._driven = False  # the newest velocity command moves the arm
        self._command = -math.inf  # simulated time of the newest velocity command [s]
        self._echo = -math.inf  # simulated time of the newest state the stack answered [s]
        self._echo_stamp = -1  # its stamp [ns]; an echo counts only when newer
        self._echo_armed = False

    def command(self, sim_time: float, moving: bool) -> None:
        """A command was applied at `sim_time`; `moving`: a nonzero velocity (a trajectory is not)."""
        with self._cond:
            self._command, self._driven = sim_time, moving
            self._cond.notify_all()

    def published(self, stamp_ns: int, sim_time: float) -> None:
        """The state of `sim_time` went out stamped `stamp_ns` (loop thread)."""
        with self._cond:
            self._published.append((stamp_ns, sim_time))

    def echo(self, stamp_ns: int) -> None:
        """The stack answered the state stamped `stamp_ns` (a stamp not published is placed at the newest
        published one before it; one older than the remembered states is ignored)."""
        with self._cond:
            if stamp_ns <= self._echo_stamp:
                return
            placed = None
            for stamp, sim_time in reversed(self._published):
                if stamp <= stamp_ns:
                    placed = sim_time
                    break
            if placed is None:
                return
            self._echo_stamp, self._echo, self._echo_armed = stamp_ns, placed, True
            self._cond.notify_all()

    def hold(self, sim_time: float) -> str:
        """Why the loop must not step past `sim_time` now ("" to step)."""
        if not self._driven:
            return ""
        if sim_time - self._command > self.lead:
            return "velocity command"
        if self._echo_armed and sim_time - self._echo > self.lead:
            return "echo"
        return ""

    def wait(self, sim_time: float, timeout: float) -> bool:
        """Waits up to `timeout` wall seconds for the stack to answer; True when the loop may step."""
        with self._cond:
            return self._cond.wait_for(lambda: not self.hold(sim_time), timeout)

    def give_up(self) -> None:
        """The stack is silent: step freely until its next command and its next echo."""
        with self._cond:
            self._driven = False
            self._echo_armed = False

    def reset(self) -> None:
        """The simulation restarted at time 0: forget every time."""
        with self._cond:
            self._published.clear()
            self._driven, self._echo_armed = False, False
            self._command = self._echo = -math.inf
            self._echo_stamp = -1
