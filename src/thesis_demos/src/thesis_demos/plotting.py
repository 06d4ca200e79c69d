"""One PNG per demonstration: force, velocity and position of the EEF on the controlled axes."""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt
import numpy as np

from thesis_demos.analysis import AXIS_INDEX, Recording, Verdict
from thesis_demos.finishing import PathRecording
from thesis_demos.insertion import TaskRecording
from thesis_demos.scenarios import SURFACE_TOLERANCE, Scenario

__all__ = ["plot", "plot_path", "plot_task"]

PEG_HALF = 0.005  # [m] the peg tool's half width (mujoco_driver tool:=peg)


def _velocity(t: np.ndarray, y: np.ndarray, span: float = 0.05) -> tuple[np.ndarray, np.ndarray]:
    """Measured velocity by differences over `span` seconds (the pose is sampled at ~500 Hz)."""
    if len(t) < 3:
        return t, np.zeros_like(t)
    step = max(1, int(span / max(np.median(np.diff(t)), 1e-4)))
    return t[step:], (y[step:] - y[:-step]) / (t[step:] - t[:-step])


def _plot_teach(scenario: Scenario, rec: Recording, verdict: Verdict, path: str) -> None:
    """Teach and replay: the taught L and each replay from above, their distance from it, the press force."""
    from teach.playback import path_distance

    fig, (ax_xy, ax_d, ax_f) = plt.subplots(3, 1, figsize=(9, 10), gridspec_kw={"height_ratios": [3, 2, 2]})
    origin = np.zeros(2)
    taught = np.zeros((0, 3))
    if rec.taught is not None:
        keep = (rec.pose_t >= rec.taught[0]) & (rec.pose_t <= rec.taught[1])
        taught = rec.pose[keep]
        origin = taught[0, :2] if len(taught) else origin
        ax_xy.plot(*((taught[:, :2] - origin) * 1e3).T, color="black", linewidth=3, alpha=0.4,
                   label="taught by hand")
    for r in rec.replays:
        end = r.end if np.isfinite(r.end) else (rec.pose_t[-1] if rec.pose_t.size else 0.0)
        keep = (rec.pose_t >= r.path_start) & (rec.pose_t <= end)
        if np.any(keep) and len(taught) >= 2:
            ax_xy.plot(*((rec.pose[keep, :2] - origin) * 1e3).T, linewidth=1, label=r.label)
            xy = [0, 1] if r.pressed else [0, 1, 2]  # pressing, Z is the force's (lower than taught)
            distance = path_distance(rec.pose[keep][:, xy], taught[:, xy]) * 1e3
            ax_d.plot(rec.pose_t[keep] - r.path_start, distance, label=r.label)
        if r.pressed:  # from the replay's start: the move to it, the touch, the press, then the path
            win = (rec.wrench_t >= r.start) & (rec.wrench_t <= end)
            zero = r.path_start if np.isfinite(r.path_start) else r.start
            ax_f.plot(rec.wrench_t[win] - zero, rec.contact_force[win, 2], alpha=0.4,
                      label="Fz (sensor, tared)")
            ax_f.plot(rec.status_t - zero, rec.force[:, 2], linewidth=1, label="Fz (contact_control)")
            ax_f.set_xlim((r.start - zero, end - zero))
            ax_f.axvline(0.0, color="green", linestyle=":", linewidth=1)
            ax_f.axhspan(scenario.press_force - SURFACE_TOLERANCE, scenario.press_force + SURFACE_TOLERANCE,
                         color="green", alpha=0.1)
    ax_xy.set_aspect("equal", adjustable="datalim")
    ax_xy.set_xlabel("x from the L's start [mm]")
    ax_xy.set_ylabel("y [mm]")
    ax_d.set_ylabel("off the taught path [mm]")
    ax_f.set_ylabel("contact force Z [N]")
    for ax in (ax_d, ax_f):
        ax.set_xlabel("time since the path started [s]")
    _finish(fig, (ax_xy, ax_d, ax_f), scenario, verdict, path)


def _finish(fig, axes, scenario: Scenario, verdict: Verdict, path: str) -> None:
    """Grids and legends, the verdict as the title, the PNG written and the figure freed."""
    for ax in axes:
        ax.grid(True, alpha=0.3)
        ax.legend(loc="upper right", fontsize=8)
    fig.suptitle(f"{scenario.title}\n{'PASS' if verdict.passed else 'FAIL'}: {verdict.summary}", fontsize=8,
                 wrap=True)
    fig.tight_layout()
    fig.savefig(path, dpi=90)
    plt.close(fig)


def plot(scenario: Scenario, rec: Recording, verdict: Verdict, path: str) -> None:
    """Writes the figure for `scenario` to `path` (PNG)."""
    if scenario.teach is not None:
        _plot_teach(scenario, rec, verdict, path)
        return
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


def plot_task(scenario: Scenario, rec: TaskRecording, verdict: Verdict, path: str) -> None:
    """Peg in hole: the tool's path from above with the true hole and the nominal one, then |F| and the depth
    past the touch point over time, a colour per step."""
    fig, (ax_xy, ax_f, ax_d) = plt.subplots(3, 1, figsize=(9, 10), gridspec_kw={"height_ratios": [3, 2, 2]})
    centre = np.asarray(rec.nominal)
    square = np.array([[-1, -1], [1, -1], [1, 1], [-1, 1], [-1, -1]], dtype=float) * PEG_HALF
    c, s = np.cos(rec.hole[3]), np.sin(rec.hole[3])
    hole = square @ np.array([[c, s], [-s, c]]) + np.asarray(rec.hole[:2]) - centre
    ax_xy.plot(*(hole * 1e3).T, color="black", linewidth=2, label="the hole (true pose)")
    ax_xy.plot(*(square * 1e3).T, color="grey", linestyle="--", linewidth=1, label="where it was said to be")
    if len(rec.pose):
        ax_xy.plot(*((rec.pose[:, :2] - centre) * 1e3).T, linewidth=1, label="tool tip")
    t = rec.feedback_t
    for name in dict.fromkeys(rec.feedback_step):
        keep = np.array([step == name for step in rec.feedback_step])
        ax_f.plot(t[keep], rec.force[keep], ".", markersize=3, label=name)
        ax_d.plot(t[keep], rec.depth[keep] * 1e3, ".", markersize=3, label=name)
    ax_f.axhline(scenario.task.max_force if scenario.task else 0.0, color="red", linestyle="--", linewidth=1)
    ax_xy.set_aspect("equal", adjustable="datalim")
    ax_xy.set_xlabel("x from the nominal hole [mm]")
    ax_xy.set_ylabel("y [mm]")
    ax_f.set_ylabel("|F| [N] (dashed: the limit)")
    ax_d.set_ylabel("depth past the touch [mm]")
    ax_d.set_xlabel("time since the task began [s]")
    _finish(fig, (ax_xy, ax_f, ax_d), scenario, verdict, path)


def plot_path(scenario: Scenario, rec: PathRecording, verdict: Verdict, path: str) -> None:
    """Curved surface: the path seen from the side over the real and the nominal cylinder, then the force
    along the tool's axis and the tool's angle to the normal along the path."""
    from thesis_demos.finishing import true_angles

    fig, (ax_side, ax_f, ax_a) = plt.subplots(3, 1, figsize=(9, 10), gridspec_kw={"height_ratios": [3, 2, 2]})
    demo = scenario.path
    radius = demo.radius if demo is not None else 0.25
    arc = np.linspace(-1.0, 1.0, 200)
    for top, style, label in ((rec.nominal_top, "--", "the cylinder as planned"),
                              (rec.truth["top"] if rec.truth else None, "-", "the cylinder (true place)")):
        if top is not None:
            x = top[0] + radius * np.sin(arc)
            z = top[2] - radius + radius * np.cos(arc)
            ax_side.plot(x * 1e3, z * 1e3, style, color="black" if style == "-" else "grey", label=label)
    if len(rec.planned):
        ax_side.plot(rec.planned[:, 0] * 1e3, rec.planned[:, 2] * 1e3, ".", color="grey", markersize=3,
                     label="the planned path")
    if len(rec.tip):
        ax_side.plot(rec.tip[:, 0] * 1e3, rec.tip[:, 2] * 1e3, linewidth=1.5, label="tool tip")
    target = demo.force if demo is not None else 10.0
    ax_f.plot(rec.progress * 100.0, rec.force, ".", markersize=3, label="along the tool's axis")
    ax_f.axhline(target, color="black", linewidth=1)
    ax_f.axhspan(target - (demo.force_rms if demo else 1.5), target + (demo.force_rms if demo else 1.5),
                 color="green", alpha=0.1)
    angles = true_angles(rec)
    if len(angles) and len(rec.pose_t) == len(angles):
        progress = np.interp(rec.pose_t, rec.feedback_t, rec.progress) if len(rec.feedback_t) else rec.pose_t
        ax_a.plot(progress * 100.0, angles, linewidth=1, label="to the true normal under the tip")
    ax_a.plot(rec.progress * 100.0, rec.angle, ".", markersize=3, label="to the normal the force reads")
    ax_a.axhline(demo.angle_max if demo else 8.0, color="red", linestyle="--", linewidth=1)
    ax_side.set_aspect("equal", adjustable="datalim")
    ax_side.set_xlabel("x [mm]")
    ax_side.set_ylabel("z [mm]")
    ax_f.set_ylabel("force [N]")
    ax_a.set_ylabel("tool's axis to the normal [deg]")
    ax_a.set_xlabel("along the path [%]")
    _finish(fig, (ax_side, ax_f, ax_a), scenario, verdict, path)
