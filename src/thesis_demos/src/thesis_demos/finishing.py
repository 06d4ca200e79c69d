"""The eighth demonstration's verdict: a path at a force over a curved part that is not where the path was
planned (contact_tasks' ~follow_path, scenarios.PathDemo), judged on the force, contact, the tool's angle to
the surface's normal and the sideways error (thesis_demos README).

Pure: no rospy.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from thesis_demos.analysis import Verdict
from thesis_demos.scenarios import PathDemo
from thesis_demos.surfaces import cylinder_normal

__all__ = ["PathRecording", "judge_path", "true_angles"]


@dataclass
class PathRecording:
    """What a path run left: the action's result, its feedback and the tool's poses.

    `truth`: the simulated driver's `~surface` (kind, radius, top, rpy), None on a robot without one;
    `nominal_top`: where the path was planned (the cylinder's highest point) [m].
    """

    outcome: str
    message: str
    result: dict[str, float]
    nominal_top: tuple[float, float, float]
    truth: dict[str, Any] | None = None
    feedback_t: np.ndarray = field(default_factory=lambda: np.zeros(0))
    progress: np.ndarray = field(default_factory=lambda: np.zeros(0))  # 0..1 along the path
    force: np.ndarray = field(default_factory=lambda: np.zeros(0))  # [N] along the tool's axis
    angle: np.ndarray = field(default_factory=lambda: np.zeros(0))  # [deg] as the force reads it
    planned: np.ndarray = field(default_factory=lambda: np.zeros((0, 3)))  # the path's positions [m]
    pose_t: np.ndarray = field(default_factory=lambda: np.zeros(0))
    tip: np.ndarray = field(default_factory=lambda: np.zeros((0, 3)))  # [m] while it followed the path
    axis: np.ndarray = field(default_factory=lambda: np.zeros((0, 3)))  # the tool's z, unit


def true_angles(rec: PathRecording) -> np.ndarray:
    """The tool's axis to the real part's normal under the tip [deg] per pose sample (the truth's cylinder);
    empty without a truth."""
    truth = rec.truth
    if not truth or truth.get("kind") != "cylinder" or not len(rec.tip):
        return np.zeros(0)
    top, radius = truth["top"], float(truth["radius"])
    normals = np.array([cylinder_normal(top, radius, p) for p in rec.tip])
    cos = np.clip(np.einsum("ij,ij->i", -rec.axis, normals), -1.0, 1.0)
    return np.degrees(np.arccos(cos))


def judge_path(demo: PathDemo, rec: PathRecording) -> Verdict:
    """PASS when the path was run to its end with the force, contact, angle and sideways error within the
    demonstration's bounds. The angle is the truth's (the real normal under the tip) when the driver gives
    one, else the action's (as the force reads it)."""
    r = rec.result
    angles = true_angles(rec)
    if len(angles):
        angle_rms, angle_max, judged = float(np.sqrt(np.mean(angles**2))), float(angles.max()), "true normal"
    else:
        angle_rms, angle_max, judged = r["normal_angle_rms"], r["normal_angle_max"], "normal read by force"
    lateral = r["lateral_error_max"]
    checks = {
        f"path {rec.outcome}: {rec.message}": rec.outcome == "succeeded",
        f"force RMS error {r['force_rms_error']:.2f} N (<= {demo.force_rms:g})": r["force_rms_error"]
        <= demo.force_rms,
        f"max |F| {r['force_max']:.1f} N (<= {demo.force_max:g})": r["force_max"] <= demo.force_max,
        f"in contact {r['contact_fraction'] * 100:.1f} % (>= {demo.contact * 100:g})": r["contact_fraction"]
        >= demo.contact,
        f"tool to {judged} RMS {angle_rms:.2f} deg (<= {demo.angle_rms:g})": angle_rms <= demo.angle_rms,
        f"max {angle_max:.2f} deg (<= {demo.angle_max:g})": angle_max <= demo.angle_max,
        f"sideways {lateral * 1e3:.2f} mm (<= {demo.lateral * 1e3:g})": lateral <= demo.lateral,
    }
    off = ""
    if rec.truth:
        top = np.asarray(rec.truth["top"], dtype=float)
        d = (top - np.asarray(rec.nominal_top)) * 1e3
        off = f"part {d[0]:+.1f}, {d[1]:+.1f}, {d[2]:+.1f} mm from nominal, not told to the path; "
    summary = (f"{off}{r['length']:.3f} m in {r['duration']:.1f} s; " + "; ".join(checks))
    figures = {"force RMS error [N]": r["force_rms_error"], "max |F| [N]": r["force_max"],
               "contact [%]": r["contact_fraction"] * 100.0, "angle RMS [deg]": angle_rms,
               "angle max [deg]": angle_max, "sideways max [mm]": lateral * 1e3,
               "length [m]": r["length"], "time [s]": r["duration"]}
    if not math.isnan(r.get("normal_angle_rms", math.nan)):
        figures["angle read by force RMS [deg]"] = r["normal_angle_rms"]
    return Verdict(all(checks.values()), summary, figures)
