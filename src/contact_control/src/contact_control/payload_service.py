"""`~payload/*` services of contact_control_node: sample the wrench at static orientations, fit the tool.

Thin rospy adapter around `payload.fit_payload`; the node feeds it every raw wrench while it samples.
"""

from __future__ import annotations

import math
import threading
from collections.abc import Callable, Sequence

import rospy
from std_srvs.srv import Trigger, TriggerRequest, TriggerResponse

from contact_control.frames import rotation_angle
from contact_control.payload import PayloadError, fit_payload, gravity_in_sensor

__all__ = ["PayloadServices"]

SAMPLES_PER_POSE = 100  # wrenches averaged per orientation (0.2 s at 500 Hz)
SAMPLE_TIMEOUT = 5.0  # [s] for those wrenches to arrive
MAX_TURN = 0.01  # [rad] the sensor turning more while sampling means the arm was not at rest


class PayloadServices:
    """`~payload/add_sample`, `~payload/identify`, `~payload/clear` (std_srvs/Trigger).

    Args:
        private_ns: Prefix of the services.
        sensor_rotation: () -> 3x3 rows of the sensor frame in the fixed frame (LookupError if unknown).
        busy: () -> a reason not to sample now ("" if fine), e.g. a running move.
        oriented: raw wrench -> the wrench with the configured sign flips (what the model explains).
        gravity: Gravity in the fixed frame [m/s^2].
    """

    def __init__(
        self,
        private_ns: str,
        sensor_rotation: Callable[[], Sequence[Sequence[float]]],
        busy: Callable[[], str],
        oriented: Callable[[Sequence[float]], list[float]],
        gravity: Sequence[float],
    ) -> None:
        self._rotation, self._busy, self._oriented, self._gravity = sensor_rotation, busy, oriented, gravity
        self._lock = threading.Lock()
        self._buffer: list[Sequence[float]] | None = None
        self._full = threading.Event()
        self.samples: list[tuple[tuple[float, float, float], list[float]]] = []
        self._services = [
            rospy.Service(private_ns + "payload/add_sample", Trigger, self._on_add),
            rospy.Service(private_ns + "payload/identify", Trigger, self._on_identify),
            rospy.Service(private_ns + "payload/clear", Trigger, self._on_clear),
        ]

    @property
    def sampling(self) -> bool:
        return self._buffer is not None

    def feed(self, raw: Sequence[float]) -> None:
        """A raw wrench (call for every one while `sampling`)."""
        buffer = self._buffer
        if buffer is not None and len(buffer) < SAMPLES_PER_POSE:
            buffer.append(raw)
            if len(buffer) == SAMPLES_PER_POSE:
                self._full.set()

    def _on_add(self, _req: TriggerRequest) -> TriggerResponse:
        why = self._busy()
        if why:
            return TriggerResponse(success=False, message=f"not sampling: {why}")
        try:
            r0 = self._rotation()
        except LookupError as err:
            return TriggerResponse(success=False, message=f"not sampling: the sensor's orientation: {err}")
        with self._lock:
            self._full.clear()
            self._buffer = []
        got = self._full.wait(SAMPLE_TIMEOUT)
        with self._lock:
            buffer, self._buffer = self._buffer or [], None
        if not got:
            return TriggerResponse(success=False, message=f"{len(buffer)} wrenches in {SAMPLE_TIMEOUT} s")
        r1 = self._rotation()
        turned = rotation_angle(r0, r1)
        if turned > MAX_TURN:
            return TriggerResponse(success=False, message=f"the sensor turned {turned:.3f} rad meanwhile")
        oriented = [self._oriented(w) for w in buffer]
        if not all(math.isfinite(v) for w in oriented for v in w):
            return TriggerResponse(success=False, message="a wrench had NaN/inf: sample again")
        mean = [sum(w[i] for w in oriented) / len(oriented) for i in range(6)]
        u = gravity_in_sensor(r1, self._gravity)
        self.samples.append((u, mean))
        g = ", ".join(f"{v:.2f}" for v in u)
        w = ", ".join(f"{v:.3f}" for v in mean)
        return TriggerResponse(
            success=True,
            message=f"sample {len(self.samples)}: gravity in the sensor frame ({g}) m/s^2, mean wrench "
            f"({w}); identify needs 3 or more orientations, 6 tilted about two axes are better",
        )

    def _on_identify(self, _req: TriggerRequest) -> TriggerResponse:
        try:
            fit = fit_payload(self.samples)
        except PayloadError as err:
            return TriggerResponse(success=False, message=str(err))
        rospy.loginfo("contact_control: payload identified: %s", fit.describe())
        return TriggerResponse(success=True, message=f"{fit.describe()}\n{fit.yaml_keys()}")

    def _on_clear(self, _req: TriggerRequest) -> TriggerResponse:
        count = len(self.samples)
        self.samples.clear()
        return TriggerResponse(success=True, message=f"{count} samples cleared")

