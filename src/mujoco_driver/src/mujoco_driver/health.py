"""mujoco_driver's health report for /diagnostics (no ROS): the simulation's real-time factor against the one
asked, the backlog dropped, MuJoCo's warnings (the package README's "Health").

The real-time factor is judged as an input rate (compliant_common.diagnostics: OK from 0.9 of the target,
WARN from 0.5, ERROR below): the stack's timing assumes the simulated sensor's rate.
"""

from __future__ import annotations

from compliant_common.diagnostics import OK, WARN, Report, rate_check

__all__ = ["driver_health"]


def driver_health(name: str, rtf: float | None, target: float, dropped: float, warnings: dict[str, int],
                  sim_time: float, mode: str, latency: tuple[float, float] | None = None) -> Report:
    """The report; `rtf` None until first measured, `target` 0 for as fast as possible; `latency` the
    stack's end to end (a wrench published -> the joint command it caused received) p50, p99 [s] over the
    last measurement period, None while no command follows a wrench."""
    report = Report(name)
    if target > 0.0:
        level, words = rate_check(rtf, target, "real-time factor")
        report.check(level, words.replace(" Hz", ""))
    if warnings:
        report.check(WARN, "MuJoCo warnings: " + ", ".join(f"{k} x{v}" for k, v in sorted(warnings.items())))
    report.value("real-time factor", "not measured" if rtf is None else f"{rtf:.3f}")
    report.value("real-time factor asked", f"{target:g}" if target > 0.0 else "as fast as possible")
    report.value("backlog dropped [s]", dropped)
    report.value("simulated time [s]", sim_time)
    report.value("joint command mode", mode)
    report.value("end to end p50 / p99 [ms]", "no commands following wrenches" if latency is None
                 else f"{latency[0] * 1e3:.2f} / {latency[1] * 1e3:.2f}")
    if report.level == OK:
        report.check(OK, f"simulating, {mode} commands")
    return report
