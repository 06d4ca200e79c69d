"""The demonstrations' verdicts: synthetic recordings that should pass, and ones that must fail."""

import numpy as np
import pytest
from harness.demo_lines import free_replays, pressed_mean
from thesis_demos.analysis import CONTACT_FORCE_BOUND, Recording, judge
from thesis_demos.scenarios import SCENARIOS, by_name

RATE = 500.0


def _recording(duration, x=None, y=None, z=None, ends=None, end_time=None, contact_z=None):
    t = np.arange(0.0, duration, 1.0 / RATE)
    pose = np.zeros((len(t), 3))
    for i, f in enumerate((x, y, z)):
        if f is not None:
            pose[:, i] = [f(ti) for ti in t]
    contact = np.zeros((len(t), 3))
    if contact_z is not None:
        contact[:, 2] = [contact_z(ti) for ti in t]
    zeros = np.zeros((len(t), 3))
    return Recording(t, pose, t, zeros, zeros, t, contact, ends or {}, end_time)


def _ramp(start, end, speed):
    return lambda t: speed * (min(max(t, start), end) - start)


def test_follower_passes_at_f_over_b_and_fails_when_too_slow():
    scenario = by_name(["follower_z"])[0]
    push = scenario.pushes[0]
    good = _recording(scenario.duration, z=_ramp(push.start, push.end, 5.0 / 30.0))
    assert judge(scenario, good).passed
    slow = _recording(scenario.duration, z=_ramp(push.start, push.end, 0.8 * 5.0 / 30.0))
    assert not judge(scenario, slow).passed


def test_follower_fails_when_the_side_push_moves_the_arm():
    scenario = by_name(["follower_z"])[0]
    push, side = scenario.pushes
    rec = _recording(
        scenario.duration, x=_ramp(side.start, side.end, 0.01), z=_ramp(push.start, push.end, 1 / 6)
    )
    verdict = judge(scenario, rec)
    assert not verdict.passed
    assert verdict.figures["motion under X/Y push [mm]"] > 2.0


def test_compliant_move_needs_force_stop_low_peak_and_hold():
    scenario = by_name(["compliant_move_z"])[0]

    def rec(ends, peak, residual=0.05):
        return _recording(
            5.0,
            z=_ramp(0.0, 2.5, -0.03),
            ends={"z": ends},
            end_time=2.5,
            contact_z=lambda t: peak if 2.4 < t < 2.6 else residual if t > 2.6 else 0.0,
        )

    assert scenario.exceeded_action == "move_away"
    verdict = judge(scenario, rec(1, 3.0))
    assert verdict.passed and "residual contact force 0.05 N" in verdict.summary
    assert not judge(scenario, rec(2, 3.0)).passed, "ended by travel, not by contact"
    assert not judge(scenario, rec(1, CONTACT_FORCE_BOUND + 1)).passed, "pressed too hard"
    pressing = judge(scenario, rec(1, 9.5, residual=9.1))  # stopped, but kept pressing on the obstacle
    assert not pressing.passed and pressing.figures["residual contact force [N]"] == pytest.approx(9.1)


def test_spring_return_and_overshoot():
    scenario = by_name(["spring_x"])[0]
    (push,) = scenario.pushes

    def x(overshoot, final):
        def f(t):
            if t < push.start:
                return 0.0
            if t < push.end:
                return 0.005
            if t < push.end + 0.3:
                return -overshoot
            return final

        return f

    assert judge(scenario, _recording(scenario.duration, x=x(0.0002, 0.0005))).passed
    assert not judge(scenario, _recording(scenario.duration, x=x(0.001, 0.0))).passed, "overshoot 20%"
    assert not judge(scenario, _recording(scenario.duration, x=x(0.0, 0.003))).passed, "did not return"


def test_hybrid_needs_travel_stop_and_z_return():
    scenario = by_name(["hybrid"])[0]
    (push,) = scenario.pushes

    def z(t):
        return 0.004 if push.start < t < push.end else 0.0

    good = _recording(8.0, x=_ramp(0.0, 6.0, -0.05), z=z, ends={"x": 2}, end_time=6.0)
    assert judge(scenario, good).passed
    short = _recording(8.0, x=_ramp(0.0, 4.0, -0.05), z=z, ends={"x": 1}, end_time=4.0)
    assert not judge(scenario, short).passed


def test_unknown_demo_name_is_refused():
    with pytest.raises(KeyError, match="unknown demo"):
        by_name(["nope"])
    assert [s.name for s in by_name([])] == [s.name for s in SCENARIOS]


def test_a_run_that_ended_before_its_push_fails_instead_of_crashing():
    scenario = by_name(["hybrid"])[0]
    early = _recording(0.5, x=_ramp(0.0, 0.5, -0.05), ends={"x": 1}, end_time=0.3)
    verdict = judge(scenario, early)
    assert not verdict.passed


def _surface_recording(force, x_travel=0.04, ended_by_travel=True):
    """Presses from t = 1 s, X moves from t = 2 s at 0.01 m/s; `force(t)` is the contact force on Z."""
    duration = 2.0 + x_travel / 0.01
    rec = _recording(
        duration + 0.5,
        x=_ramp(2.0, duration, -0.01),
        ends={"x": 2 if ended_by_travel else 0, "z": 0},
        end_time=duration,
        contact_z=force,
    )
    rec.follow_up_time = 2.0
    return rec


def test_surface_following_passes_at_the_target_despite_fast_stick_slip_dips():
    scenario = by_name(["surface_following"])[0]
    # The simulated tool face sliding on the block: the raw force drops to 2.5 N for one 2 ms step every
    # 16 ms; its 50 ms means stay at the target.
    rec = _surface_recording(lambda t: 2.5 if round(t * RATE) % 8 == 0 else 11.07)
    verdict = judge(scenario, rec)
    assert verdict.passed, verdict.summary
    assert abs(verdict.figures["mean contact force over the travel [N]"] - 10.0) < 0.1
    assert verdict.figures["raw sample std (65 Hz stick-slip) [N]"] > 2.0


@pytest.mark.parametrize(
    "force, travel, by_travel, why",
    [
        (lambda t: 7.0, 0.04, True, "pressing too lightly"),
        (lambda t: 10.0 + 3.0 * np.sin(2 * np.pi * t), 0.04, True, "a slow swing of +-3 N"),
        (lambda t: 10.0, 0.02, False, "X stopped short"),
    ],
)
def test_surface_following_fails(force, travel, by_travel, why):
    verdict = judge(by_name(["surface_following"])[0], _surface_recording(force, travel, by_travel))
    assert not verdict.passed, why


def _teach_recording(press_force, free=((0.0003, 0.001), (0.0006, 0.0024)), legs=(-0.08, -0.04)):
    """Taught from 1 to 3 s (X leg, then Y); replays: free 1x, free 2x (path error RMS, max) and pressed
    from 10 s (its path from 12 to 20 s, `press_force(t)` the contact force on Z)."""
    from thesis_demos.analysis import Replayed

    def x(t):
        return legs[0] * min(max(t - 1.0, 0.0), 1.0)

    def y(t):
        return legs[1] * min(max(t - 2.0, 0.0), 1.0)

    rec = _recording(21.0, x=x, y=y, contact_z=press_force)
    rec.taught = (1.0, 3.0)
    (rms1, max1), (rms2, max2) = free
    rec.replays = [
        Replayed("free space 1x", 1.0, False, True, "ok", rms1, max1, start=4.0, path_start=5.0, end=7.0),
        Replayed("free space 2x", 2.0, False, True, "ok", rms2, max2, start=7.0, path_start=8.0, end=9.5),
        Replayed("pressing", 0.08, True, True, "ok", 0.0001, 0.0002, 10.0, 9.0, 11.0, start=10.0,
                 path_start=12.0, end=20.0),
    ]
    return rec


def _teach_scenario():
    from thesis_demos.scenarios import teach_and_replay

    return teach_and_replay((0.04, 0.02), (-0.08, -0.04))


def test_teach_and_replay_passes_with_the_path_kept_and_the_force_held():
    verdict = judge(_teach_scenario(), _teach_recording(lambda t: 10.3 if round(t * RATE) % 2 else 9.7))
    assert verdict.passed, verdict.summary
    assert verdict.figures["taught X leg [mm]"] == pytest.approx(-80.0, abs=0.5)
    assert verdict.figures["free space 2x: path error max [mm]"] == pytest.approx(2.4)
    assert verdict.figures["pressing: mean contact force [N]"] == pytest.approx(10.0, abs=0.05)
    # What the tests of `make demo` read back from the line (tests/harness/demo_lines.py).
    figures = [verdict.figures[f"free space {k}: path error {m} [mm]"]
               for k in ("1x", "2x") for m in ("RMS", "max")]
    assert free_replays(verdict.summary) == pytest.approx(figures, abs=0.005)
    assert pressed_mean(verdict.summary) == pytest.approx(10.0, abs=0.05)


@pytest.mark.parametrize(
    "force, free, legs, why",
    [
        (lambda t: 10.0, ((0.0003, 0.001), (0.0025, 0.006)), (-0.08, -0.04), "2x off the path"),
        (lambda t: 10.0 + 2.0 * (t > 15.0), ((0.0003, 0.001), (0.0006, 0.0024)), (-0.08, -0.04),
         "the force left the band"),
        (lambda t: 10.0, ((0.0003, 0.001), (0.0006, 0.0024)), (-0.03, -0.04), "a short X leg"),
    ],
)
def test_teach_and_replay_fails(force, free, legs, why):
    verdict = judge(_teach_scenario(), _teach_recording(force, free, legs))
    assert not verdict.passed, why


def test_teach_and_replay_fails_when_a_replay_failed_or_did_not_run():
    rec = _teach_recording(lambda t: 10.0)
    rec.replays[2].success, rec.replays[2].message = False, "stopped at 21%: force limit"
    assert "stopped at 21%" in judge(_teach_scenario(), rec).summary
    rec.replays = rec.replays[:2]
    verdict = judge(_teach_scenario(), rec)
    assert not verdict.passed and "1 of the 3 replays did not run" in verdict.summary
