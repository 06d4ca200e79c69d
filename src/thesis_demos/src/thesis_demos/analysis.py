"""Judging a recorded demonstration: the figures a person would read off the plots.

Pure: numpy only. A `Recording` holds time series sampled from the live stack; `judge` returns a
`Verdict` with a one-line summary and the measured figures.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from thesis_demos.scenarios import SURFACE_SETTLE, SURFACE_TOLERANCE, TEACH_PATH_MAX, TEACH_PATH_RMS, Scenario

__all__ = ["CONTACT_FORCE_BOUND", "RESIDUAL_WINDOW", "SURFACE_AVERAGING", "Recording", "Replayed", "Verdict",
           "judge", "moving_mean"]

AXIS_INDEX = {"x": 0, "y": 1, "z": 2}
# Compliant move stops on contact without pressing harder than this [N]. Why: the arm is a stiff
# position-controlled cobot. From the touch until the filtered force passes the 0.5 N limit, and the
# stop has gone through jog_arm and the joint servos, the tool keeps closing in at V_desired (0.01 m/s)
# for some 30-50 ms, i.e. ~0.5 mm into a hard obstacle, at the servo's Cartesian stiffness of ~20 N/mm.
# The bound must stay under contact_control's 25 N global limit, so that the move ends by its own law
# and never by the safety latch; a cobot's own protective stop is far higher (around 150 N).
CONTACT_FORCE_BOUND = 20.0
# The residual contact force after a compliant move is the mean over this last part of the recording [s],
# which runs `Scenario.settle` (1 s) past the end of the move and its backing off: sensor noise averages out.
RESIDUAL_WINDOW = 0.5
# Surface following judges the spread of the contact force's means over this window [s] (a 20 Hz reading).
SURFACE_AVERAGING = 0.05


@dataclass
class Replayed:
    """One replay of the taught program (teach's ~replay action): its result and when it ran [s, recording
    time]; `path_start` is when the path began (after the move to its start, and the press when pressing)."""

    label: str
    speed: float
    pressed: bool
    success: bool
    message: str
    path_error_rms: float  # [m] the action's result: distance from the recorded path
    path_error_max: float  # [m]
    force_mean: float = 0.0  # [N] the action's (contact_control's filtered force on the press axis)
    force_min: float = 0.0
    force_max: float = 0.0
    start: float = float("nan")
    path_start: float = float("nan")
    end: float = float("nan")


@dataclass
class Recording:
    """Time series of one run; times are seconds since the laws were set."""

    pose_t: np.ndarray  # (N,)
    pose: np.ndarray  # (N, 3) tool tip position, base frame [m]
    status_t: np.ndarray  # (M,)
    force: np.ndarray  # (M, 3) preprocessed force the controller used, control frame [N]
    command: np.ndarray  # (M, 3) commanded linear velocity [m/s]
    wrench_t: np.ndarray  # (K,)
    contact_force: np.ndarray  # (K, 3) tared sensor force rotated to the base frame [N]
    end_conditions: dict[str, int] = field(default_factory=dict)  # axis -> AxisState end condition
    move_end_time: float | None = None
    follow_up_time: float | None = None  # when the scenario's follow-up laws were sent (surface following)
    taught: tuple[float, float] | None = None  # teach and replay: when the recording ran [s]
    replays: list[Replayed] = field(default_factory=list)


@dataclass
class Verdict:
    passed: bool
    summary: str
    figures: dict[str, float]


def _window(t: np.ndarray, start: float, end: float) -> np.ndarray:
    return (t >= start) & (t <= end)


def _max(values: np.ndarray) -> float:
    """Largest value, NaN for an empty window (a run that ended early fails its checks, not the tool)."""
    return float(np.max(values)) if values.size else float("nan")


def _slope(t: np.ndarray, y: np.ndarray) -> float:
    if len(t) < 3:
        return float("nan")
    return float(np.polyfit(t, y, 1)[0])


def _at(rec: Recording, time: float) -> np.ndarray:
    """The tool position at `time` (nearest sample)."""
    return rec.pose[int(np.argmin(np.abs(rec.pose_t - time)))]


def _before(rec: Recording, time: float) -> np.ndarray:
    """The tool position just before `time`, e.g. where a push starts."""
    return _at(rec, time - 0.05)


def judge(scenario: Scenario, rec: Recording) -> Verdict:
    """Applies the scenario's acceptance criteria to a recording."""
    return _JUDGES[scenario.name](scenario, rec)


def _follower(scenario: Scenario, rec: Recording) -> Verdict:
    push, side_push = scenario.pushes
    law = scenario.laws["z"]
    start = _before(rec, push.start)
    # Steady state: the second half of the push, after the filters have settled.
    win = _window(rec.pose_t, push.start + push.duration / 2, push.end)
    v_z = _slope(rec.pose_t[win], rec.pose[win, 2])
    expected = push.force[2] / law.damping
    during = _window(rec.pose_t, push.start, push.end + 0.5)
    drift_xy = _max(np.linalg.norm(rec.pose[during, :2] - start[:2], axis=1))
    side = _window(rec.pose_t, side_push.start, side_push.end + 0.5)
    side_move = _max(np.linalg.norm(rec.pose[side] - _before(rec, side_push.start), axis=1))
    tail = _window(rec.pose_t, rec.pose_t[-1] - 1.0, rec.pose_t[-1])
    rest_speed = abs(_slope(rec.pose_t[tail], rec.pose[tail, 2]))
    figures = {
        "v_z [m/s]": v_z,
        "F/b [m/s]": expected,
        "xy drift during Z push [mm]": drift_xy * 1e3,
        "motion under X/Y push [mm]": side_move * 1e3,
        "speed after release [mm/s]": rest_speed * 1e3,
    }
    ok_speed = abs(v_z - expected) <= 0.15 * expected
    passed = ok_speed and drift_xy < 2e-3 and side_move < 2e-3 and rest_speed < 2e-3
    summary = (
        f"Z followed the {push.force[2]:.0f} N push at {v_z:.3f} m/s (F/b = {expected:.3f}); "
        f"X/Y drift {drift_xy * 1e3:.2f} mm; an X/Y push moved it {side_move * 1e3:.2f} mm; "
        f"after release {rest_speed * 1e3:.2f} mm/s"
    )
    return Verdict(passed, summary, figures)


def _residual_force(rec: Recording, window: float = RESIDUAL_WINDOW) -> float:
    """Mean |contact force| along Z [N] over the recording's last `window` seconds: what still presses."""
    if not rec.wrench_t.size:
        return float("nan")
    tail = rec.wrench_t >= rec.wrench_t[-1] - window
    return float(abs(np.mean(rec.contact_force[tail, 2])))


def _compliant(scenario: Scenario, rec: Recording) -> Verdict:
    law = scenario.laws["z"]
    limit = law.force_limit
    direction = 1.0 if law.velocity > 0 else -1.0  # down (-1) onto the obstacle in every robot package so far
    start = rec.pose[0]
    end = rec.pose[-1]
    travel = float(direction * (end[2] - start[2]))
    ended_by_force = rec.end_conditions.get("z") == 1
    peak = _max(np.abs(rec.contact_force[:, 2]))
    tail = _window(rec.pose_t, rec.pose_t[-1] - 0.8, rec.pose_t[-1])
    hold = float(np.ptp(rec.pose[tail, 2])) if np.any(tail) else float("nan")
    residual = _residual_force(rec)
    figures = {
        "travel down [mm]": travel * 1e3,
        "peak contact force [N]": peak,
        "contact force bound [N]": CONTACT_FORCE_BOUND,
        "motion while holding [mm]": hold * 1e3,
        "residual contact force [N]": residual,
        "force limit [N]": limit,
    }
    passed = travel > 0.02 and ended_by_force and peak < CONTACT_FORCE_BOUND and hold < 1e-3
    if scenario.exceeded_action == "move_away":
        passed = passed and residual < limit  # no standing press on the obstacle
    reason = "force limit" if ended_by_force else f"end condition {rec.end_conditions.get('z')}"
    summary = (
        f"moved {travel * 1e3:.1f} mm {'up' if direction > 0 else 'down'}, stopped by {reason}, "
        f"peak contact force {peak:.2f} N "
        f"(bound {CONTACT_FORCE_BOUND:.0f} N), {scenario.exceeded_action.replace('_', ' ')}: "
        f"residual contact force {residual:.2f} N (limit {limit:g} N), then held within {hold * 1e3:.2f} mm"
    )
    return Verdict(passed, summary, figures)


def _spring(scenario: Scenario, rec: Recording) -> Verdict:
    (push,) = scenario.pushes
    axis = AXIS_INDEX[scenario.controlled[0]]
    sign = float(np.sign(push.force[axis]))
    x0 = _before(rec, push.start)[axis]
    rel = sign * (rec.pose[:, axis] - x0)
    during = _window(rec.pose_t, push.start, push.end)
    after = rec.pose_t > push.end
    excursion = _max(rel[during])
    overshoot = max(0.0, _max(-rel[after]))
    final = float(abs(rel[-1]))
    figures = {
        "excursion [mm]": excursion * 1e3,
        "return error [mm]": final * 1e3,
        "overshoot [mm]": overshoot * 1e3,
    }
    passed = excursion > 1e-3 and final < 2e-3 and overshoot < 0.1 * excursion
    summary = (
        f"pushed {abs(push.force[axis]):.0f} N for {push.duration:.0f} s it gave way "
        f"{excursion * 1e3:.1f} mm; "
        f"released it came back to {final * 1e3:.2f} mm of its start, overshoot {overshoot * 1e3:.2f} mm"
    )
    return Verdict(passed, summary, figures)


def _hybrid(scenario: Scenario, rec: Recording) -> Verdict:
    (push,) = scenario.pushes
    x_law = scenario.laws["x"]
    start = rec.pose[0]
    travel_x = float(abs(rec.pose[-1, 0] - start[0]))
    ended_by_travel = rec.end_conditions.get("x") == 2
    z0 = _before(rec, push.start)[2]
    during = _window(rec.pose_t, push.start, push.end)
    z_excursion = _max(rec.pose[during, 2] - z0)
    end_t = rec.move_end_time if rec.move_end_time is not None else rec.pose_t[-1]
    z_back = float(abs(_at(rec, end_t)[2] - z0))
    figures = {
        "x travel [m]": travel_x,
        "max path deviation [m]": x_law.max_travel,
        "z excursion under push [mm]": z_excursion * 1e3,
        "z return error [mm]": z_back * 1e3,
    }
    passed = (
        ended_by_travel and abs(travel_x - x_law.max_travel) < 0.02 and z_excursion > 1e-3 and z_back < 2e-3
    )
    summary = (
        f"X travelled {travel_x:.3f} m and stopped at its {x_law.max_travel:.2f} m max path deviation"
        f"{'' if ended_by_travel else ' (NOT by MAX_TRAVEL)'}; Z gave way {z_excursion * 1e3:.1f} mm "
        f"to the push and returned to {z_back * 1e3:.2f} mm"
    )
    return Verdict(passed, summary, figures)


def moving_mean(t: np.ndarray, y: np.ndarray, span: float) -> np.ndarray:
    """Means of `y` over consecutive windows of `span` seconds (sliding by one sample)."""
    if len(t) < 2:
        return y.copy()
    n = max(1, round(span / max(float(np.median(np.diff(t))), 1e-4)))
    if len(y) < n:
        return np.array([y.mean()]) if y.size else y
    return np.convolve(y, np.ones(n) / n, mode="valid")


def _surface(scenario: Scenario, rec: Recording) -> Verdict:
    """Surface following: the contact force on Z over X's travel, after SURFACE_SETTLE, against the target.

    The force is the driver's sensor (tared before the laws, so the tool's weight is out; rotated to the base
    frame: the block pushing the tool up is +Z), not the controller's filtered estimate. The peak on touching
    (before X starts) and over the whole run (X's stop at the end of its travel kicks the force up too) are
    reported, not judged: had one tripped contact_control's 25 N global limit before the end, the move would
    have ended before X's travel, failing the verdict.
    The mean is of the raw samples; the spread is that of its SURFACE_AVERAGING means (what a 20 Hz force
    reading shows), because the simulated flat tool face sliding on the block drops the raw force for one
    2 ms step every ~15 ms (stick-slip at ~65 Hz, far above anything the arm or a hand follows); the raw
    spread is reported too.
    """
    follow_up = scenario.follow_up
    target = follow_up.target if follow_up else float("nan")
    x_law = follow_up.laws["x"] if follow_up else scenario.laws["x"]
    start = rec.follow_up_time if rec.follow_up_time is not None else float("nan")
    end = rec.move_end_time if rec.move_end_time is not None else (rec.pose_t[-1] if rec.pose_t.size else 0.0)
    mean, raw_std, spread, low, high = _pressed_force(rec, start + SURFACE_SETTLE, end)
    nan = float("nan")
    ended_by_travel = rec.end_conditions.get("x") == 2
    known = rec.pose_t.size and rec.follow_up_time is not None
    travel_x = float(abs(_at(rec, end)[0] - _at(rec, start)[0])) if known else 0.0
    peak = _max(rec.contact_force[_window(rec.wrench_t, -np.inf, start), 2]) if rec.wrench_t.size else nan
    peak_all = _max(rec.contact_force[:, 2]) if rec.wrench_t.size else nan
    figures = {
        "target contact force [N]": target,
        "mean contact force over the travel [N]": mean,
        "spread of 50 ms means (std) [N]": spread,
        "50 ms means min [N]": low,
        "50 ms means max [N]": high,
        "raw sample std (65 Hz stick-slip) [N]": raw_std,
        "tolerance [N]": SURFACE_TOLERANCE,
        "x travel [m]": travel_x,
        "max path deviation [m]": x_law.max_travel,
        "peak contact force (touching) [N]": peak,
        "peak contact force (whole run) [N]": peak_all,
    }
    passed = (
        abs(mean - target) <= SURFACE_TOLERANCE
        and target - SURFACE_TOLERANCE <= low
        and high <= target + SURFACE_TOLERANCE
        and ended_by_travel
        and abs(travel_x - x_law.max_travel) < 0.01
    )
    summary = (
        f"X travelled {travel_x * 1e3:.1f} mm{'' if ended_by_travel else ' (NOT by MAX_TRAVEL)'} while Z "
        f"pressed with a mean {mean:.2f} N, spread {spread:.2f} N (std of 50 ms means, "
        f"{low:.2f}..{high:.2f} N; raw std {raw_std:.2f} N) for a target of {target:g} +- "
        f"{SURFACE_TOLERANCE:g} N; peak on touching {peak:.2f} N, over the run {peak_all:.2f} N"
    )
    return Verdict(passed, summary, figures)


def _pressed_force(rec: Recording, start: float, end: float) -> tuple[float, float, float, float, float]:
    """The sensor's contact force on Z between `start` and `end` [s] as a person reads it: mean and std of the
    raw samples, then the std, min and max of its SURFACE_AVERAGING means (NaN for an empty window)."""
    win = _window(rec.wrench_t, start, end)
    force = rec.contact_force[win, 2]
    if not force.size:
        nan = float("nan")
        return nan, nan, nan, nan, nan
    smooth = moving_mean(rec.wrench_t[win], force, SURFACE_AVERAGING)
    return (float(np.mean(force)), float(np.std(force)), float(np.std(smooth)), float(np.min(smooth)),
            float(np.max(smooth)))


def _teach(scenario: Scenario, rec: Recording) -> Verdict:
    """Teach and replay: the hand-guided L was recorded; each free-space replay stayed within TEACH_PATH_RMS /
    TEACH_PATH_MAX of it (the action's own measure: the tool's distance from the recorded path); the pressed
    one held the target within SURFACE_TOLERANCE along the path (the sensor's force, surface following's
    rule: after SURFACE_SETTLE, the SURFACE_AVERAGING means)."""
    assert scenario.teach is not None
    legs = scenario.teach.legs
    figures: dict[str, float] = {}
    problems: list[str] = []
    taught = np.zeros(3)
    if rec.taught is not None and rec.pose_t.size:
        taught = _at(rec, rec.taught[1]) - _at(rec, rec.taught[0])
    figures["taught X leg [mm]"], figures["taught Y leg [mm]"] = taught[0] * 1e3, taught[1] * 1e3
    if not all(np.sign(taught[i]) == np.sign(legs[i]) and abs(taught[i]) >= 0.7 * abs(legs[i])
               for i in (0, 1)):
        problems.append(f"the taught L is {taught[0] * 1e3:.0f} x {taught[1] * 1e3:.0f} mm, not about "
                        f"{legs[0] * 1e3:.0f} x {legs[1] * 1e3:.0f}")
    parts = []
    target = scenario.press_force
    for r in rec.replays:
        figures[f"{r.label}: path error RMS [mm]"] = r.path_error_rms * 1e3
        figures[f"{r.label}: path error max [mm]"] = r.path_error_max * 1e3
        if not r.success:
            problems.append(f"{r.label}: {r.message}")
        if r.pressed:
            mean, _raw, spread, low, high = _pressed_force(rec, r.path_start + SURFACE_SETTLE, r.end)
            figures.update({f"{r.label}: mean contact force [N]": mean,
                            f"{r.label}: spread of 50 ms means (std) [N]": spread,
                            f"{r.label}: 50 ms means min [N]": low,
                            f"{r.label}: 50 ms means max [N]": high,
                            f"{r.label}: controller's force min [N]": r.force_min,
                            f"{r.label}: controller's force max [N]": r.force_max})
            if not (abs(mean - target) <= SURFACE_TOLERANCE and target - SURFACE_TOLERANCE <= low
                    and high <= target + SURFACE_TOLERANCE):
                problems.append(f"{r.label}: the force left {target:g} +- {SURFACE_TOLERANCE:g} N")
            parts.append(f"{r.label} held {mean:.2f} N ({low:.2f}..{high:.2f} N, 50 ms means) along the "
                         f"path, {r.path_error_max * 1e3:.2f} mm max off it")
        else:
            if not (r.path_error_rms < TEACH_PATH_RMS and r.path_error_max < TEACH_PATH_MAX):
                problems.append(f"{r.label}: {r.path_error_rms * 1e3:.2f} mm RMS, "
                                f"{r.path_error_max * 1e3:.2f} mm max off the path")
            parts.append(f"{r.label} {r.path_error_rms * 1e3:.2f} mm RMS, "
                         f"{r.path_error_max * 1e3:.2f} mm max")
    if len(rec.replays) < 3:
        problems.append(f"{3 - len(rec.replays)} of the 3 replays did not run")
    summary = (f"taught {taught[0] * 1e3:.0f} x {taught[1] * 1e3:.0f} mm by hand; replayed: "
               + "; ".join(parts) + (f" -- {'; '.join(problems)}" if problems else ""))
    return Verdict(not problems, summary, figures)


_JUDGES = {
    "follower_z": _follower,
    "compliant_move_z": _compliant,
    "spring_x": _spring,
    "hybrid": _hybrid,
    "surface_following": _surface,
    "teach_and_replay": _teach,
}
