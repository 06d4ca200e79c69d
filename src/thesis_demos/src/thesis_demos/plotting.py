"""One PNG per demonstration: force, velocity and position of the EEF on the controlled axes."""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt
import numpy as np

from thesis_demos.analysis import AXIS_INDEX, Recording, Verdict
from thesis_demos.scenarios import Scenario

__all__ = ["plot"]


def _velocity(t: np.ndarray, y: np.ndarray, span: float = 0.05) -> tuple[np.ndarray, np.ndarray]:
    """Measured velocity by differences over `span` seconds (the pose is sampled at ~500 Hz)."""
    if len(t) < 3:
        return t, np.zeros_like(t)
    step = max(1, int(span / max(np.median(np.diff(t)), 1e-4)))
    return t[step:], (y[step:] - y[:-step]) / (t[step:] - t[:-step])


def plot(scenario: Scenario, rec: Recording, verdict: Verdict, path: str) -> None:
    """Writes the figure for `scenario` to `path` (PNG)."""
    fig, (ax_f, ax_v, ax_p) = plt.subplots(3, 1, sharex=True, figsize=(9, 7.5))
    for axis in scenario.controlled:
        i = AXIS_INDEX[axis]
        ax_f.plot(rec.status_t, rec.force[:, i], label=f"F{axis} (preprocessed)")
        if len(rec.wrench_t):
            ax_f.plot(rec.wrench_t, rec.contact_force[:, i], alpha=0.4, label=f"F{axis} (sensor, tared)")
        ax_v.plot(rec.status_t, rec.command[:, i], label=f"v{axis} commanded")
        tv, v = _velocity(rec.pose_t, rec.pose[:, i])
        ax_v.plot(tv, v, alpha=0.7, label=f"v{axis} measured")
        ax_p.plot(rec.pose_t, (rec.pose[:, i] - rec.pose[0, i]) * 1e3, label=f"{axis} - {axis}0")
    if scenario.follow_up is not None:
        # The target band and the time the follow-up laws (surface following: the X move) were sent.
        up = scenario.follow_up
        ax_f.axhspan(up.target - up.tolerance, up.target + up.tolerance, color="green", alpha=0.1)
        if rec.follow_up_time is not None:
            for ax in (ax_f, ax_v, ax_p):
                ax.axvline(rec.follow_up_time, color="green", linestyle=":", linewidth=1)
    for ax in (ax_f, ax_v, ax_p):
        for push in scenario.pushes:
            ax.axvspan(push.start, push.end, color="orange", alpha=0.15)
        if rec.move_end_time is not None:
            ax.axvline(rec.move_end_time, color="red", linestyle="--", linewidth=1)
        ax.grid(True, alpha=0.3)
        ax.legend(loc="upper right", fontsize=8)
    ax_f.set_ylabel("force [N]")
    ax_v.set_ylabel("velocity [m/s]")
    ax_p.set_ylabel("position [mm]")
    ax_p.set_xlabel("time since the law was set [s]  (shaded: push; dashed: move ended)")
    mark = "PASS" if verdict.passed else "FAIL"
    fig.suptitle(f"{scenario.title}\n{mark}: {verdict.summary}", fontsize=9)
    fig.tight_layout()
    fig.savefig(path, dpi=90)
    plt.close(fig)
