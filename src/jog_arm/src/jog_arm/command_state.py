"""The twist command being followed: its value, frame and receive time, and what refuses or drops it.

A command is accepted or refused when it arrives (:meth:`CommandState.set`); each cycle then asks whether
there is one to follow now (:meth:`CommandState.status`) and, if so, for the twist in root axes
(:meth:`CommandState.in_root_axes`).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from compliant_common.typedefs import FloatArray

from jog_arm.command_frames import CommandFrame, CommandFrames
from jog_arm.settings import JogSettings
from jog_arm.status import StatusCode

__all__ = ["CommandResult", "CommandState"]


@dataclass(frozen=True)
class CommandResult:
    """Outcome of :meth:`CommandState.set` (and `JogCalcs.set_command`).

    Attributes:
        accepted: True if the command is now the target.
        reason: Why it was refused ("" if accepted).
    """

    accepted: bool
    reason: str = ""


_ACCEPTED = CommandResult(True)


class CommandState:
    """The current twist command and the modes (pause, suspension) that refuse commands.

    Args:
        settings: Validated parameters (units, default frame, timeouts, singularity length scale).
        frames: Where command frames are resolved.
    """

    def __init__(self, settings: JogSettings, frames: CommandFrames) -> None:
        self._frames = frames
        self._unitless = settings.command_in_type == "unitless"
        self.retune(settings)
        self._default_frame = settings.default_cmd_frame
        self._state_timeout = settings.joint_state_timeout
        # Root-axes twists are weighted like the solver's Jacobian: linear part / singularity_length_scale.
        self._inv_length = 1.0 / settings.singularity_length_scale
        self._row_weights = np.array([self._inv_length] * 3 + [1.0] * 3)
        self._twist = np.zeros(6)  # SI units, in its own frame
        self._twist_root = np.zeros(6)  # in root axes, weighted (set once by `set` if the frame never moves)
        self._frame: CommandFrame | None = None
        self._time: float | None = None  # receive time; None: no command (none yet, dropped, resumed)
        #: The current command is all zeros (or there is none).
        self.zero = True
        self._rejected = ""  # why the last command was refused ("" if accepted)
        self._drop_reason = ""  # why the last command was dropped (shown while there is none)
        self._suspended = ""  # why commands are refused for now (e.g. the ROS master is lost)
        #: Whether :meth:`pause` is in effect.
        self.paused = False


    def retune(self, settings: JogSettings) -> None:
        """Live tuning: the unitless scales and the command timeout (the next command is scaled anew)."""
        if self._unitless:
            self._unit_scales = (float(settings.scale_linear), float(settings.scale_rotational))
        else:
            self._unit_scales = (1.0, 1.0)
        self._cmd_timeout = settings.incoming_cmd_timeout
    def set(self, twist: Sequence[float], frame: str, now: float) -> CommandResult:
        """Accepts (or refuses, see `JogCalcs.set_command`) `twist` in `frame` received at `now` [s]."""
        if self.paused:
            return CommandResult(False, "paused: commands are ignored until resume")
        if self._suspended:
            return CommandResult(False, f"suspended: {self._suspended}")
        reason = ""
        if len(twist) != 6:
            reason = f"a twist has 6 components, got {len(twist)}"
        elif not all(map(math.isfinite, twist)):
            reason = f"non-finite value in twist {list(twist)}"
        elif self._unitless and any(abs(v) > 1.0 for v in twist):
            reason = f"unitless twist components must be within [-1, 1], got {list(twist)}"
        if not reason:
            resolved = self._frames.resolve((frame or self._default_frame).lstrip("/"))
            if resolved is None:
                reason = f"unknown frame {frame!r}: not in the robot model nor added"
        if reason:
            self._rejected = reason
            return CommandResult(False, reason)
        assert resolved is not None  # no reason: the frame resolved
        self._rejected = ""
        # Plain floats: at this size numpy's per-call overhead dominates, more so with cold caches.
        lin, rot = self._unit_scales
        vx, vy, vz, wx, wy, wz = twist
        vx, vy, vz, wx, wy, wz = vx * lin, vy * lin, vz * lin, wx * rot, wy * rot, wz * rot
        self._twist[:] = (vx, vy, vz, wx, wy, wz)
        self.zero = not any(twist)
        self._frame = resolved
        rows = resolved.static_rows
        if rows is not None:  # rotate once, not every cycle
            (a, b, c), (d, e, f), (g, h, i) = rows
            k = self._inv_length
            self._twist_root[:] = (
                (a * vx + b * vy + c * vz) * k,
                (d * vx + e * vy + f * vz) * k,
                (g * vx + h * vy + i * vz) * k,
                a * wx + b * wy + c * wz,
                d * wx + e * wy + f * wz,
                g * wx + h * wy + i * wz,
            )
        self._time = now
        self._drop_reason = ""
        return _ACCEPTED

    def drop(self, reason: str) -> None:
        """Forgets the current command; `reason` is the status until the next one."""
        self._time = None
        self.zero = True
        self._drop_reason = reason

    def suspend(self, reason: str) -> None:
        """Drops the command and refuses new ones until :meth:`unsuspend`."""
        self._suspended = reason
        self.drop(reason)

    def unsuspend(self) -> None:
        """Accepts commands again (the suspension's drop reason is no longer shown)."""
        if self._suspended and self._drop_reason == self._suspended:
            self._drop_reason = ""
        self._suspended = ""

    def pause(self) -> None:
        """Refuses commands until :meth:`resume`."""
        self.paused = True

    def resume(self) -> None:
        """Accepts commands again; the old one is dropped."""
        self.paused = False
        self._time = None
        self.zero = True

    def status(self, now: float, state_time: float | None) -> tuple[StatusCode, str]:
        """Whether there is a command to follow at `now`: NO_WARNING, or the reason there is none.

        `state_time` is the joint state's receive time (None: its age is not checked; -inf: wait for a
        fresh one): a stale joint state ranks below the modes and above the command's own faults.
        """
        if self.paused:
            return StatusCode.PAUSED, "paused"
        if self._suspended:
            return StatusCode.PAUSED, f"suspended: {self._suspended}"
        if state_time is not None and now - state_time > self._state_timeout:
            message = (
                f"no joint state for {now - state_time:.3f} s (joint_state_timeout): stopping"
                if state_time > -math.inf
                else "waiting for a joint state received after the clock jump"
            )
            return StatusCode.STALE_JOINT_STATE, message
        if self._rejected:
            return StatusCode.INVALID_COMMAND, f"command rejected: {self._rejected}"
        if self._time is None:
            return StatusCode.STALE_COMMAND, self._drop_reason or "no command received yet"
        if now - self._time > self._cmd_timeout:
            age = now - self._time
            return StatusCode.STALE_COMMAND, f"no command for {age:.3f} s (incoming_cmd_timeout)"
        return StatusCode.NO_WARNING, "zero command" if self.zero else ""

    def in_root_axes(self, q: FloatArray) -> FloatArray:
        """The command's twist in root axes at configuration `q`, linear part divided by
        `singularity_length_scale` (a shared array, valid until the next call). Call only while following
        a command; for a frame that moves, after the cycle's Jacobian (see `CommandFrames.rotation`)."""
        x = self._twist_root
        frame = self._frame
        assert frame is not None  # a command is being followed
        if frame.static is None:
            rot = self._frames.rotation(frame, q)
            np.dot(rot, self._twist[:3], out=x[:3])
            np.dot(rot, self._twist[3:], out=x[3:])
            x *= self._row_weights
        return x
