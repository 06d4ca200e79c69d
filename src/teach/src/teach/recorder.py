"""Recording a program: samples at a fixed rate, keyframes, then the simplified `Program` (no ROS here)."""

from __future__ import annotations

import math
from collections.abc import Sequence

from teach.program import Program, ProgramError, Waypoint, check_name, now_iso
from teach.simplify import simplify

__all__ = ["Recorder", "Sample"]

Sample = tuple[float, tuple[float, ...], tuple[float, ...], tuple[float, ...], tuple[float, ...]]
"""(t [s], joints, position (x, y, z) [m], orientation (x, y, z, w), wrench (fx..tz) [N, Nm])."""


class Recorder:
    """One recording at a time: `start`, `add` per sample, `keyframe`, `finish` -> Program.

    Args:
        robot: the arm's identity (what a replay compares).
        base_frame, tip_frame: the tool pose's frames.
        rate: the sampling rate [Hz] (the node's timer; kept in the program).
        position_tolerance, angle_tolerance: the simplification's [m], [rad].
    """

    def __init__(self, robot: str, base_frame: str, tip_frame: str, rate: float,
                 position_tolerance: float, angle_tolerance: float) -> None:
        self.robot, self.base_frame, self.tip_frame = robot, base_frame, tip_frame
        self.rate = rate
        self.position_tolerance, self.angle_tolerance = position_tolerance, angle_tolerance
        self.name = ""
        self.joint_names: tuple[str, ...] = ()
        self._samples: list[Sample] = []
        self._keys: set[int] = set()
        self._key_pending = False
        self._t0 = 0.0

    @property
    def recording(self) -> bool:
        return bool(self.name)

    @property
    def count(self) -> int:
        return len(self._samples)

    def start(self, name: str, t: float) -> None:
        """Starts recording `name` at time `t` [s].

        Raises:
            ProgramError: Already recording, or a bad name.
        """
        if self.recording:
            raise ProgramError(f"already recording '{self.name}' ({self.count} samples): stop it first")
        self.name = check_name(name)
        self.joint_names = ()
        self._samples, self._keys, self._key_pending, self._t0 = [], set(), False, t

    def add(self, t: float, joint_names: Sequence[str], joints: Sequence[float], position: Sequence[float],
            orientation: Sequence[float], wrench: Sequence[float]) -> None:
        """One sample at `t`, the pose's own time (ignored when not recording, or when not newer than the
        last); the first fixes the joint names."""
        if not self.recording or not (_finite(position) and _finite(orientation)):
            return
        names = tuple(joint_names)
        if not self.joint_names:
            self.joint_names = names
        elif names != self.joint_names:
            return  # another joint state layout (a gripper's own message): not this arm's
        rel = t - self._t0
        if self._samples and rel <= self._samples[-1][0]:
            return  # no newer than the last sample (the same pose looked up again): it adds nothing
        if not self._samples and rel < 0.0:  # the first pose is older than the start call
            self._t0, rel = t, 0.0
        if self._key_pending:
            self._keys.add(len(self._samples))
            self._key_pending = False
        self._samples.append((rel, tuple(joints), tuple(position), tuple(orientation), tuple(wrench)))

    def keyframe(self) -> int:
        """Marks the next sample as a keyframe; returns the number of keyframes so far.

        Raises:
            ProgramError: Not recording.
        """
        if not self.recording:
            raise ProgramError("not recording: start a recording first")
        self._key_pending = True
        return len(self._keys) + 1

    def cancel(self) -> None:
        self.name = ""
        self._samples = []

    def finish(self, bag: str = "") -> Program:
        """Ends the recording: the program, simplified to waypoints.

        Raises:
            ProgramError: Not recording, or fewer than two samples (nothing to replay).
        """
        if not self.recording:
            raise ProgramError("not recording: nothing to stop")
        samples, name = self._samples, self.name
        self.cancel()
        if len(samples) < 2:
            raise ProgramError(f"recording '{name}' has {len(samples)} sample(s): no joint state or tool "
                               "pose arrived while recording (is the arm's driver running?)")
        keep = [i in self._keys for i in range(len(samples))]
        kept = simplify([s[0] for s in samples], [s[2] for s in samples], [s[3] for s in samples], keep,
                        self.position_tolerance, self.angle_tolerance)
        waypoints = tuple(Waypoint(s[0], s[1], s[2], s[3], s[4], keep[i])
                          for i, s in ((i, samples[i]) for i in kept))
        return Program(name=name, robot=self.robot, joint_names=self.joint_names, base_frame=self.base_frame,
                       tip_frame=self.tip_frame, waypoints=waypoints, rate=self.rate,
                       position_tolerance=self.position_tolerance, angle_tolerance=self.angle_tolerance,
                       samples=len(samples), recorded=now_iso(), bag=bag)


def _finite(values: Sequence[float]) -> bool:
    return all(math.isfinite(v) for v in values)
