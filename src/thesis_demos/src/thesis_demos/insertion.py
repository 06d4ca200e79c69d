"""The seventh demonstration's verdict: a contact_tasks task run in a scene of its own (the hole fixture and
the peg tool, scenarios.TaskDemo), judged on depth, time and peaks (thesis_demos README).

Pure: no rospy.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from thesis_demos.analysis import Verdict
from thesis_demos.scenarios import TaskDemo

__all__ = ["TaskRecording", "judge_task"]


@dataclass
class TaskRecording:
    """What a task run left: the action's result, its feedback over time and the tool's path.

    `hole`: where the hole truly was (x, y, plate top z [m], yaw [rad]) in the base frame; `nominal` the
    block's top centre where the task was told to look (x, y [m]).
    """

    outcome: str
    message: str
    steps: list[str]
    step_times: list[float]
    peak_force: float
    peak_torque: float
    hole: tuple[float, float, float, float]
    nominal: tuple[float, float]
    feedback_t: np.ndarray = field(default_factory=lambda: np.zeros(0))
    feedback_step: list[str] = field(default_factory=list)
    depth: np.ndarray = field(default_factory=lambda: np.zeros(0))  # [m] past the touch point
    force: np.ndarray = field(default_factory=lambda: np.zeros(0))  # |F| [N]
    pose_t: np.ndarray = field(default_factory=lambda: np.zeros(0))
    pose: np.ndarray = field(default_factory=lambda: np.zeros((0, 3)))  # tool tip [m]


def judge_task(demo: TaskDemo, rec: TaskRecording) -> Verdict:
    """PASS when the task succeeded with the tool at least `demo.depth` under the plate's top, within
    `demo.within` seconds and the peaks; the summary gives the hole's offset from nominal and each step."""
    seconds = float(sum(rec.step_times))
    depth = rec.hole[2] - float(rec.pose[-1, 2]) if len(rec.pose) else math.nan
    off = (rec.hole[0] - rec.nominal[0], rec.hole[1] - rec.nominal[1])
    checks = {
        f"task {rec.outcome}: {rec.message}": rec.outcome == "succeeded",
        f"{depth * 1e3:.1f} mm deep (>= {demo.depth * 1e3:g})": depth >= demo.depth,
        f"{seconds:.1f} s (<= {demo.within:g})": seconds <= demo.within,
        f"peak |F| {rec.peak_force:.1f} N (<= {demo.max_force:g})": rec.peak_force <= demo.max_force,
        f"peak |T| {rec.peak_torque:.2f} Nm (<= {demo.max_torque:g})": rec.peak_torque <= demo.max_torque,
    }
    steps = ", ".join(f"{n} {t:.1f} s" for n, t in zip(rec.steps, rec.step_times, strict=True))
    summary = (f"hole {off[0] * 1e3:+.1f}, {off[1] * 1e3:+.1f} mm and {math.degrees(rec.hole[3]):+.1f} deg "
               f"from nominal, not told to the task; {'; '.join(checks)}; steps: {steps}")
    figures = {"depth [mm]": depth * 1e3, "time [s]": seconds, "peak |F| [N]": rec.peak_force,
               "peak |T| [Nm]": rec.peak_torque, "hole offset x [mm]": off[0] * 1e3,
               "hole offset y [mm]": off[1] * 1e3, "hole yaw [deg]": math.degrees(rec.hole[3])}
    return Verdict(all(checks.values()), summary, figures)
