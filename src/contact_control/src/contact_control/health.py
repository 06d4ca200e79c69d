"""contact_control's health report for /diagnostics (no ROS): the sensor's rate and age, the safety state with
its reason, the running move, the noise floor and the zero's drift (levels: the README's "Health").

ERROR: no wrench for the stale timeout, an invalid or over-limit wrench, a missing transform, a lost ROS
master (the node holds the arm still in each). WARN: zeroing the sensor; the sensor's measured rate below
RATE_WARN of the configured one (`lp_filter_delta_t`); the zero drifted more than DRIFT_WARN noise stds; the
robot stopped by itself (jog_arm reports it as ERROR; requests here are refused until it recovers).
"""

from __future__ import annotations

import math
from collections.abc import Sequence

from compliant_common.diagnostics import ERROR, OK, WARN, Report, rate_check

from contact_control.axes import (
    AXES,
    LAW_NAMES,
    SAFETY_NAMES,
    SAFETY_NAN,
    SAFETY_NO_TF,
    SAFETY_OVER_LIMIT,
    SAFETY_STALE,
    SAFETY_ZEROING,
)
from contact_control.cycle import CycleResult
from contact_control.noise_floor import NoiseFloor
from contact_control.params import ContactControlSettings

__all__ = ["DRIFT_WARN", "contact_health"]

DRIFT_WARN = 5.0  # the zero drifted this many raw noise stds (the largest force axis): WARN, tare it
_FAULTS = (SAFETY_NAN, SAFETY_OVER_LIMIT, SAFETY_STALE, SAFETY_NO_TF)


def contact_health(name: str, s: ContactControlSettings, result: CycleResult, message: str,
                   sample_period: float | None, wrench_age: float | None, timeout: float,
                   floor: NoiseFloor | None, drift: Sequence[float] | None, master: str,
                   guiding: bool, robot_stop: str = "") -> Report:
    """The report; `wrench_age` [s] since the newest wrench arrived (None: none yet), `master` the lost
    master's reason and `robot_stop` why the robot stopped by itself ('' while it answers / runs)."""
    report = Report(name)
    safety = SAFETY_NAMES.get(result.safety, str(result.safety))
    if master:
        report.check(ERROR, master)
    if robot_stop:
        report.check(WARN, f"{robot_stop}: requests refused until jog_arm_server/recover")
    if result.safety in _FAULTS:
        report.check(ERROR, message or safety)
    elif result.safety == SAFETY_ZEROING:
        report.check(WARN, message or safety)
    expected = 1.0 / s.lp_filter_delta_t
    measured = None if sample_period is None else 1.0 / sample_period
    if result.safety not in _FAULTS:  # a stale sensor's rate says nothing new
        report.check(*rate_check(measured, expected, "wrench"))
    report.value("safety", safety)
    report.value("robot", robot_stop or "running (no stop reported by jog_arm)")
    report.value("wrench rate [Hz]", "not measured" if measured is None else f"{measured:.1f}")
    report.value("wrench rate expected [Hz]", f"{expected:.1f} (lp_filter_delta_t)")
    report.value("newest wrench age [s]", "none yet" if wrench_age is None else f"{wrench_age:.3f}")
    report.value("stale timeout [s]", timeout)
    active = [f"{axis}={LAW_NAMES.get(law, law)}" for axis, law in zip(AXES, result.laws, strict=True) if law]
    what = "guiding" if guiding else "move"
    report.value("move", f"{what} {result.move_id}: {', '.join(active)}" if result.move_active else "none")
    if floor is not None:
        report.value("noise std force [N]", max(floor.std[:3]))
        report.value("noise std filtered force [N]", max(floor.filtered[:3]))
    if drift is not None:
        shift = math.sqrt(sum(d * d for d in drift[:3]))
        report.value("zero drift force [N]", shift)
        if floor is not None and max(floor.std[:3]) > 0.0 and shift > DRIFT_WARN * max(floor.std[:3]):
            report.check(WARN, f"the sensor's zero drifted {shift:.2g} N since the last tare (~tare it at "
                               "rest)")
    report.value("message", message or "none")
    if report.level == OK and not report.message:
        report.check(OK, f"{what} {result.move_id} running" if result.move_active else "idle, sensor fresh")
    return report
