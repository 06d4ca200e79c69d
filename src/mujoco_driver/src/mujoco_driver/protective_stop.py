"""A UR controller's protective stop as ur_robot_driver reports it (no ROS; the README's *Driver emulation*).

The safety system stops the arm when the TCP force exceeds its limit. The arm holds; the safety mode reads
PROTECTIVE_STOP and the program that streams ROS commands (External Control) stops. Recovery is the
driver's: the dashboard's ``unlock_protective_stop`` (refused until ``unlock_after`` seconds have passed,
as UR's dashboard server refuses an early unlock) brings the safety mode back to NORMAL, then
``resend_robot_program`` (or the dashboard's ``play``) starts the program again; only then do commands move
the arm.
"""

from __future__ import annotations

import math

import numpy as np

__all__ = ["NORMAL", "PROTECTIVE_STOP", "ProtectiveStop"]

# ur_dashboard_msgs/SafetyMode values
NORMAL = 1
PROTECTIVE_STOP = 3


class ProtectiveStop:
    """The safety mode and program state of an emulated UR controller.

    Args:
        force_limit: The safety configuration's TCP force limit [N] (the force's magnitude).
        unlock_after: Seconds after the stop before an unlock is accepted.
    """

    def __init__(self, force_limit: float, unlock_after: float) -> None:
        if not (math.isfinite(force_limit) and force_limit > 0.0 and unlock_after >= 0.0):
            raise ValueError(f"protective stop: force_limit > 0 and unlock_after >= 0, got {force_limit}, "
                             f"{unlock_after}")
        self.force_limit, self.unlock_after = force_limit, unlock_after
        self.reason = ""  # why the safety system stopped the arm; "" in NORMAL
        self.program_running = True
        self._stopped_at = -math.inf

    @property
    def safety_mode(self) -> int:
        return PROTECTIVE_STOP if self.reason else NORMAL

    def check(self, wrench: np.ndarray, t: float) -> bool:
        """One published TCP wrench at time ``t`` [s]; True exactly when it stops the arm."""
        if self.reason:
            return False
        force = float(np.linalg.norm(wrench[:3]))
        if not force > self.force_limit:
            return False
        self.reason = f"protective stop: TCP force {force:.0f} N over the safety limit {self.force_limit:g} N"
        self.program_running, self._stopped_at = False, t
        return True

    def unlock(self, t: float) -> tuple[bool, str]:
        """The dashboard's unlock_protective_stop at time ``t``: (success, the dashboard's answer)."""
        if not self.reason:
            return True, "Protective stop releasing (there was none)"
        wait = self._stopped_at + self.unlock_after - t
        if wait > 0.0:
            return False, (f"Cannot unlock protective stop until {self.unlock_after:g}s after occurrence "
                           f"({wait:.1f} s more). Always inspect the cause of a protective stop first")
        self.reason = ""
        return True, "Protective stop releasing"

    def play(self) -> tuple[bool, str]:
        """resend_robot_program / the dashboard's play: (success, answer); refused in a protective stop."""
        if self.reason:
            return False, "Failed to execute: the robot is in a protective stop (unlock it first)"
        self.program_running = True
        return True, "Starting program"

    def reset(self) -> None:
        """Back to the start (the simulation was reset): NORMAL, the program running."""
        self.reason, self.program_running, self._stopped_at = "", True, -math.inf
