"""jog_arm_server's health report for /diagnostics (no ROS): the last cycle's status in levels (the README's
"Health").

ERROR: no joint state or a stale one, a halt at a singularity or a joint limit (the arm is held), the robot
stopped by itself (its driver's reason). WARN:
slowing for a singularity or a joint limit, joint velocities scaled down, the contact guard acting, a clamp
being released, an invalid command.
OK: following commands (also at the collaborative speed cap: the values name the cap and the body region),
idle (no command), paused for a named-pose move.
"""

from __future__ import annotations

from compliant_common.diagnostics import ERROR, OK, WARN, Report

from jog_arm.stage import JogCycle
from jog_arm.status import StatusCode

__all__ = ["LEVELS", "jog_health"]

LEVELS = {
    StatusCode.NO_JOINT_STATE: ERROR,
    StatusCode.STALE_JOINT_STATE: ERROR,
    StatusCode.HALT_FOR_SINGULARITY: ERROR,
    StatusCode.HALT_FOR_JOINT_LIMIT: ERROR,
    StatusCode.ROBOT_STOPPED: ERROR,
    StatusCode.DECELERATE_FOR_SINGULARITY: WARN,
    StatusCode.DECELERATE_FOR_JOINT_LIMIT: WARN,
    StatusCode.JOINT_VELOCITY_SCALED: WARN,
    StatusCode.CONTACT_GUARD: WARN,
    StatusCode.CLAMP_RELEASE: WARN,
    StatusCode.INVALID_COMMAND: WARN,
}
_WORDS = {StatusCode.NO_WARNING: "following commands", StatusCode.STALE_COMMAND: "idle (no command)",
          StatusCode.PAUSED: "paused (a named-pose move)"}


def jog_health(name: str, cycle: JogCycle | None, cycles_per_second: float | None, expected: float,
               master: str, region: str = "off", robot_stop: str = "") -> Report:
    """The report from the last cycle (None: none yet), the cycles run per second since the last report,
    the collaborative speed cap's body region and why the robot stopped by itself ("" = it did not)."""
    report = Report(name)
    if master:
        report.check(ERROR, master)
    if robot_stop:  # also when no cycle runs (publish_on_command with no twist)
        report.check(ERROR, f"{robot_stop} (recover: the driver's recovery, then ~recover)")
    if cycle is None:
        report.check(ERROR, "no cycle yet (no joint state)")
    else:
        status = cycle.status
        report.check(LEVELS.get(status, OK), cycle.message or _WORDS.get(status, status.name))
        report.value("status", status.name)
        report.value("condition number", cycle.condition)
        report.value("speed scale", cycle.scale)
        cap = cycle.speed_cap
        report.value("speed cap [m/s]", f"{cap:.3f}" if cap < float("inf") else "none")
    report.value("body region (ISO/TS 15066)", region)
    report.value("cycles [Hz]", "not measured" if cycles_per_second is None else f"{cycles_per_second:.1f}")
    report.value("cycles expected [Hz]", f"{expected:.1f} (1 / pub_period)")
    return report
