"""/diagnostics for a node: its `Report` (compliant_common.diagnostics) built every `poll` seconds in a daemon
thread on the monotonic clock (never on the control path), published once a second and at once when its level
gets worse (a fault is on /diagnostics within `poll`, not within a second). The last fault stays in the
values (`last fault`, seconds ago) so a passing one is still seen.
"""

from __future__ import annotations

import time
from collections.abc import Callable

import rospy
from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus, KeyValue

from compliant_common.diagnostics import ERROR, Report
from compliant_common.ros_time import MonotonicTimer

__all__ = ["DiagnosticsPublisher"]


class DiagnosticsPublisher:
    """Publishes `build()` on /diagnostics; `build` runs in this object's thread (take the node's lock there).

    Args:
        build: Makes the node's report (name, level, message, values).
        hardware_id: The status's hardware_id (the robot, the sensor frame).
        period: [s] between publications while the level holds.
        poll: [s] between reports (a worse level is published at once).
    """

    def __init__(self, build: Callable[[], Report], hardware_id: str = "", period: float = 1.0,
                 poll: float = 0.1) -> None:
        self._build = build
        self._hardware_id = hardware_id
        self._period = period
        self._pub = rospy.Publisher("/diagnostics", DiagnosticArray, queue_size=10)
        self._last_sent = -float("inf")
        self._last_level = -1
        self._fault: tuple[float, str] | None = None  # (monotonic time, words) of the last ERROR
        self._clock = "simulated (/clock)" if rospy.get_param("/use_sim_time", False) else "wall"
        self._timer = MonotonicTimer(poll, self._on_poll, "diagnostics")

    def close(self) -> None:
        self._timer.shutdown()

    def _on_poll(self, _event: object) -> None:
        report = self._build()
        now = time.monotonic()
        if report.level >= ERROR:
            self._fault = (now, report.message)
        worse = report.level > self._last_level
        if not worse and now - self._last_sent < self._period:
            return
        if self._fault is not None:
            since, words = self._fault
            report.value("last fault", f"{now - since:.1f} s ago: {words}")
        else:
            report.value("last fault", "none")
        report.value("clock", self._clock)
        status = DiagnosticStatus(level=report.level, name=report.name, message=report.message or "ok",
                                  hardware_id=self._hardware_id,
                                  values=[KeyValue(key=k, value=v) for k, v in report.values])
        msg = DiagnosticArray(status=[status])
        msg.header.stamp = rospy.Time.now()
        try:
            self._pub.publish(msg)
        except rospy.ROSException:  # shutting down
            return
        self._last_sent, self._last_level = now, report.level
