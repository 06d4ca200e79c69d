"""CompliantPipeline: the wrench-to-joint-command chain of one arm, with no ROS (see the package README).

The data path, top to bottom:

    joint state --------------------------------------------> jog stage (measured q) --> model frames
    wrench ---> contact stage (frames from the model) ---> twist ---> jog stage ---> joint command
    outside twist (keyboard, GUI) ---> contact guard -------------> jog stage ---> joint command
    tick (time) ---> stale wrench: zero twist / halt ---------------> jog stage ---> gap fill / rate cycle

Every timing rule is here or in the two stages it calls: the clock-jump check on each input, the contact
stage's stale-data schedule, the jog stage's cycle schedule, and `next_due` that joins them. A node only
reads the clock, calls in under one lock, publishes what comes out and sleeps until `next_due`.
"""

from __future__ import annotations

import collections
import time
from collections.abc import Callable, Sequence
from typing import NamedTuple

from compliant_common.clock import ClockWatch
from contact_control.cycle import CycleResult
from contact_control.params import ContactControlSettings
from contact_control.request import ForceControlRequest, LawsRequest
from contact_control.stage import ZERO, Answer, ContactStage, PoseSource, Velocity
from jog_arm.settings import JogSettings
from jog_arm.stage import JogCycle, JogStage

__all__ = ["NOTHING", "CompliantPipeline", "PipelineOutput", "PipelineStatus"]

ECHOES_KEPT = 16  # own twists remembered to recognise their copies coming back over the topic


class PipelineStatus(NamedTuple):
    """What `CompliantPipeline.status` reports."""

    contact: CycleResult
    contact_message: str
    jog: JogCycle | None


class PipelineOutput(NamedTuple):
    """What one call produced: a new one per call (immutable), or `NOTHING`.

    Attributes:
        twist: contact_control's twist (velocity_command_frame) to publish for observers, or None.
        cycle: The jog cycle that ran (its joint command if `cycle.publish`), or None.
    """

    twist: Velocity | None
    cycle: JogCycle | None


#: A call that produced nothing (shared: no allocation for the calls that mostly produce nothing).
NOTHING = PipelineOutput(None, None)


def _output(twist: Velocity | None, cycle: JogCycle | None) -> PipelineOutput:
    return NOTHING if twist is None and cycle is None else PipelineOutput(twist, cycle)


class CompliantPipeline:
    """contact_control -> jog_arm for one arm, in-process; see the module docstring.

    Not thread-safe: the node holds one lock around every call, and reads each call's time `t` under it
    (every input's `t` is checked for a clock jump against the monotonic clock read in the call: a time
    read before waiting for the lock would look like a step back).

    Args:
        contact: contact_control's settings.
        jog: jog_arm's settings.
        urdf_xml: The robot description.
        outside_poses: Poses (in contact's fixed frame) of frames the robot model lacks, e.g. from tf;
            None: such frames are unavailable.
        monotonic: The monotonic clock.

    Raises:
        KinematicsError, SettingsError: jog_arm's configuration does not fit the robot model.
    """

    def __init__(
        self,
        contact: ContactControlSettings,
        jog: JogSettings,
        urdf_xml: str,
        outside_poses: PoseSource | None = None,
        monotonic: Callable[[], float] = time.monotonic,
    ) -> None:
        self._monotonic = monotonic
        self._outside = outside_poses
        self._fixed = contact.fixed_frame
        self.contact = ContactStage(contact, self._pose, monotonic)
        # The guard on outside twists reads contact_control's compensated force, in-process.
        self.jog = JogStage(jog, urdf_xml, lambda: self.contact.contact, monotonic)
        self._twist_frame = contact.velocity_command_frame
        self._clock = ClockWatch(stop_tolerance=max(0.5, 2.0 * jog.incoming_cmd_timeout))
        self._sent: collections.deque[tuple[float, Velocity]] = collections.deque(maxlen=ECHOES_KEPT)
        # The model frames a wrench will ask for, computed when the joint state arrives (off the wrench path).
        self._warm = sorted(f for f in self.contact.frames_used if self.jog.frames.has(f, self._fixed))

    def frames_from_outside(self) -> list[str]:
        """The configured frames the robot model lacks (they need `outside_poses`)."""
        return sorted(f for f in self.contact.frames_used if not self.jog.frames.has(f, self._fixed))

    def _pose(self, frame: str) -> list[list[float]]:
        pose = self.jog.frames.pose(frame, self._fixed)
        if pose is not None:
            return pose
        if self._outside is None:
            raise LookupError(f"{frame!r} is not a frame of the robot model")
        return self._outside(frame)

    # --- inputs ---
    def on_joint_state(self, names: Sequence[str], positions: Sequence[float], t: float) -> PipelineOutput:
        """A joint state received at `t` [s]."""
        out = self._check_clock(t)
        self.contact.on_joint_state(names, positions)  # the bias map's offset at these joints (if any)
        if self.jog.on_joint_state(names, positions, t):
            # The poses the next wrench needs, computed now (the joint state leads the wrench by half a
            # period in the simulation; the jog stage prepares its Jacobian likewise).
            for frame in self._warm:
                self.jog.frames.pose(frame, self._fixed)
        return out

    def on_wrench(
        self, wrench: Sequence[float], frame: str, stamp: float | None, t: float
    ) -> PipelineOutput:
        """A wrench in `frame` with header time `stamp` (None: unstamped) received at `t` [s]: the contact
        laws' twist, and at once the joint command for it (publish_on_command)."""
        out = self._check_clock(t)
        if out.twist is not None:  # the clock jumped: this wrench belongs to the old time
            return out
        return self._to_jog(self.contact.on_wrench(wrench, frame, stamp, t), t, out)

    def from_contact(self, twist: Velocity | None, t: float) -> PipelineOutput:
        """A twist contact_control made outside a wrench or a tick (a stop request's zero), for jog_arm."""
        return self._to_jog(twist, t, NOTHING)

    def _to_jog(self, twist: Velocity | None, t: float, out: PipelineOutput) -> PipelineOutput:
        """contact_control's twist (if any) -> jog_arm, as an inside command (no contact guard): the output
        with this twist and the cycle it ran (None if none); `out` unchanged without a twist."""
        if twist is None:
            return out
        self._sent.append((t, twist))
        return PipelineOutput(twist, self.jog.on_twist(twist, self._twist_frame, t, outside=False))

    def on_twist(
        self, twist: Sequence[float], frame: str, stamp: float, t: float
    ) -> PipelineOutput:
        """A twist from an outside source (keyboard, GUI) with header time `stamp`, received at `t` [s].

        The pipeline's own twists, published for observers on a topic it also listens to, come back here:
        they are recognised by stamp and values and dropped (they were handled when they were made).
        """
        out = self._check_clock(t)
        if self._is_echo(twist, stamp):
            return out
        return _output(out.twist, self.jog.on_twist(twist, frame, t, outside=True))

    def _is_echo(self, twist: Sequence[float], stamp: float) -> bool:
        """Whether `twist` is one this pipeline sent: same values, stamped within 1 us of one it made."""
        values = tuple(twist)
        return any(abs(stamp - t) < 1e-6 and values == sent for t, sent in self._sent)

    def on_twist_publishers(self, count: int) -> None:
        """The number of publishers on the outside twist topic (a decrease can end an outside command)."""
        self.jog.on_publishers(count)

    # --- time ---
    def next_due(self) -> float:
        """When `tick` has work next [s]."""
        return min(self.contact.next_due(), self.jog.next_due())

    def tick(self, t: float) -> PipelineOutput:
        """Every time-driven duty at `t`: the stale-wrench check (a zero twist, the move's end), then the jog
        cycle due (a fixed-rate cycle, or a gap fill between twists)."""
        out = self._check_clock(t)
        if t >= self.contact.next_due():
            out = self._to_jog(self.contact.tick(t), t, out)
        cycle = self.jog.tick(t)
        if cycle is not None:
            out = PipelineOutput(out.twist, cycle)
        return out

    def prepare(self) -> None:
        """Work for the next cycle, off the path from wrench to command: the contact force for the guard,
        the jogger's Jacobian. Call after publishing."""
        self.contact.update_contact()
        self.jog.prepare()

    def _check_clock(self, t: float) -> PipelineOutput:
        """`NOTHING`, or on a clock jump what stopping both stages produced (the zero twist in `twist`)."""
        jump = self._clock.observe(t, self._monotonic())
        if jump is None:
            return NOTHING
        note = jump.describe()
        self.jog.clock_jumped(note)
        self._sent.clear()
        return self._to_jog(self.contact.clock_jumped(note, t) or ZERO, t, NOTHING)

    # --- requests and status ---
    def configure(
        self, request: ForceControlRequest | LawsRequest, t: float, per_axis: bool = False
    ) -> Answer:
        """A ConfigureForceControl (or, `per_axis`, a ConfigureLaws) request: (ok, code, message, move_id),
        the laws in words or the reason for refusing. Nothing changes when it is refused."""
        return self.contact.configure(request, t, per_axis)

    def stop(self, reason: str, t: float) -> PipelineOutput:
        """Ends the running move; the zero twist goes to jog_arm at once."""
        return self.from_contact(self.contact.stop(reason), t)

    def status(self) -> PipelineStatus:
        """Both stages' state for the status topics: contact_control's last cycle and message, jog_arm's
        last cycle (None before the first)."""
        result, message = self.contact.status()
        return PipelineStatus(result, message, self.jog.last_cycle)

    # --- master ---
    def master_lost(self, reason: str) -> PipelineOutput:
        """The graph is broken: the move ends, the jogger stops and refuses commands until `master_back`."""
        twist = self.contact.master_lost(reason)
        self.jog.suspend(reason)
        return _output(twist, None)

    def master_back(self) -> None:
        self.contact.master_back()
        self.jog.unsuspend()
