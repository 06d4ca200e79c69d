"""The low-pass filter, the limit arithmetic and the cycle monitor, table-driven."""

from __future__ import annotations

import numpy as np
import pytest

from jog_arm import CycleMonitor, JointLimiter, LowPassFilter, singularity_scale


@pytest.mark.parametrize("coeff", [1.0, 2.0, 2.5, 10.0])
def test_filter_dc_gain_is_one(coeff: float) -> None:
    lpf = LowPassFilter(coeff, 3)
    target = [0.7, -1.3, 0.0]
    for _ in range(400):
        out = lpf.filter(target)
    np.testing.assert_allclose(out, target, rtol=1e-12)  # the fork's filter settled at 4/3 of this


@pytest.mark.parametrize("coeff", [1.0, 2.0, 10.0])
def test_filter_step_response_rises_without_overshoot(coeff: float) -> None:
    lpf = LowPassFilter(coeff, 1)
    outs = [lpf.filter([1.0])[0] for _ in range(200)]
    assert np.all(np.diff(outs) >= 0.0)
    assert max(outs) <= 1.0 + 1e-12


def test_filter_reset_to_current_state_gives_no_startup_jump() -> None:
    lpf = LowPassFilter(2.0, 2)
    lpf.reset([0.4, -0.2])
    np.testing.assert_allclose(lpf.filter([0.4, -0.2]), [0.4, -0.2])  # steady from the first sample
    fresh = LowPassFilter(2.0, 2)  # without the reset the first output would be a third of the state
    assert fresh.filter([0.4, -0.2])[0] == pytest.approx(0.4 / 3)


def test_filter_refuses_ringing_coefficient() -> None:
    with pytest.raises(ValueError, match="low_pass_filter_coeff"):
        LowPassFilter(0.5, 1)


@pytest.mark.parametrize(
    ("condition", "toward", "expected"),
    [
        (5.0, True, 1.0),
        (7.0, True, 1.0),
        (9.5, True, 0.5),
        (12.0, True, 0.0),
        (30.0, True, 0.0),
        (9.5, False, 1.0),  # moving away is never slowed
        (30.0, False, 1.0),
    ],
)
def test_singularity_scale(condition: float, toward: bool, expected: float) -> None:
    assert singularity_scale(condition, 7.0, 12.0, toward) == pytest.approx(expected)


def limiter() -> JointLimiter:
    """Two joints: ±1 and ±2 rad, 1 and 2 rad/s, 10 rad/s², margin 0.1 rad, slow-down zone 0.2 rad, 100 Hz."""
    return JointLimiter(
        [-1.0, -2.0], [1.0, 2.0], [1.0, 2.0], [10.0, 10.0], margin=0.1, slowdown_width=0.2, period=0.01
    )


@pytest.mark.parametrize(
    ("q", "dq", "expected"),
    [
        ([0.0, 0.0], [0.5, 0.5], 1.0),  # far from the stops
        ([0.9, 0.0], [0.5, 0.5], 0.0),  # joint 0 at its stop (1 - 0.1), moving toward it
        ([0.9, 0.0], [-0.5, 0.5], 1.0),  # ... moving away
        ([0.95, 0.0], [-0.5, 0.0], 1.0),  # inside the margin, moving away
        ([0.85, 0.0], [0.5, 0.0], 0.5),  # ramp: 0.05 rad left of the 0.2 rad zone allows 1 x 0.25 rad/s
        ([0.0, -1.8], [0.0, -2.0], 0.5),  # joint 1: 0.1 rad left allows 2 x 0.1 / 0.2 = 1 rad/s
        ([0.0, -1.899], [0.5, -2.0], 0.01 / 2.0),  # 0.001 rad left: ramp allows 0.01 rad/s
        ([0.0, 1.7], [0.0, 2.0], (np.sqrt(0.1**2 + 20 * 0.2) - 0.1) / 2.0),  # braking from 2 rad/s binds
    ],
)
def test_position_scale(q: list[float], dq: list[float], expected: float) -> None:
    lim = limiter()
    scale = lim.position_scale(q, dq)
    # Independent check: the scaled speed toward each stop stays within the three caps.
    for qi, vi, lo, hi, vmax, amax in zip(
        q, dq, lim.lower_stop, lim.upper_stop, [1.0, 2.0], [10.0, 10.0], strict=True
    ):
        d = hi - qi if vi > 0 else qi - lo
        if vi == 0 or d < 0:
            continue
        speed = abs(vi) * scale
        assert speed <= vmax * d / 0.2 + 1e-12
        assert speed**2 / (2 * amax) + speed * 0.01 <= d + 1e-12
    assert scale == pytest.approx(expected)


def test_velocity_scale_scales_whole_vector() -> None:
    lim = limiter()
    assert lim.velocity_scale([0.5, 1.0]) == 1.0
    assert lim.velocity_scale([2.0, 1.0]) == pytest.approx(0.5)
    assert lim.velocity_scale([0.5, -4.0]) == pytest.approx(0.5)


def test_acceleration_limit_scales_the_change_as_a_whole() -> None:
    lim = limiter()  # 10 rad/s² x 0.01 s = 0.1 rad/s per cycle
    out, limited = lim.limit_acceleration([0.0, 0.0], [1.0, 0.5])
    assert limited
    np.testing.assert_allclose(out, [0.1, 0.05])  # same direction, largest change 0.1
    out, limited = lim.limit_acceleration([0.3, 0.3], [0.35, 0.25])
    assert not limited and out == [0.35, 0.25]


def test_a_brake_changes_velocity_at_the_brake_scale() -> None:
    lim = JointLimiter([-1.0, -2.0], [1.0, 2.0], [1.0, 2.0], [10.0, 10.0], margin=0.1, slowdown_width=0.2,
                       period=0.01, brake_scale=4.0)
    out, _, _ = lim.limit([0.0, 0.0], [0.0, 0.0], [1.0, 0.5], settle=True)
    np.testing.assert_allclose(out, [0.9, 0.45])  # 0.1 rad/s per cycle
    out, _, _ = lim.limit([0.0, 0.0], [0.0, 0.0], [1.0, 0.5], settle=True, brake=True)
    np.testing.assert_allclose(out, [0.6, 0.3])  # four times that, the direction kept


def test_step_guard_never_crosses_a_stop() -> None:
    lim = limiter()
    assert lim.step_scale([0.899, 0.0], [1.0, 1.0]) == pytest.approx(0.1)  # 0.001 rad left, 0.01 step
    assert lim.step_scale([0.899, 0.0], [-1.0, 1.0]) == 1.0
    assert lim.within_stops([0.9, -1.9]) and not lim.within_stops([0.95, 0.0])


def test_cycle_monitor_counts_missed_cycles() -> None:
    monitor = CycleMonitor(0.002)
    for t in (0.0, 0.002, 0.004, 0.010, 0.012):  # 0.004 -> 0.010 skips two cycles
        monitor.tick(t)
    summary = monitor.summary()
    assert (summary["cycles"], summary["missed"]) == (5, 2)
    assert summary["max_gap_ms"] == pytest.approx(6.0)
    monitor.reset()
    assert monitor.tick(1.0) == 0 and monitor.summary()["missed"] == 0


def test_publish_on_command_gap_filler_runs_only_when_twists_stop() -> None:
    from jog_arm.timing import next_fill_time

    period = 0.002
    # Twists every 2 ms until 0.1 s (one of them 0.95 periods late, two in a row missing), the filler
    # sleeping until its next due time like the node's thread.
    twists = [k * 0.002 for k in range(50) if k not in (40, 41)]
    twists[25] += 0.0019
    last_twist, last_fill, fills = -1.0, -1.0, []
    for k in range(1, 200_000):  # 1 us steps
        t = k * 1e-6
        if twists and t >= twists[0]:
            last_twist = twists.pop(0)
        if t >= next_fill_time(last_twist, last_fill, period):
            last_fill = t
            fills.append(t)
    # One fill 2.5 periods after the twist before the missing ones (0.078 s); none for the late twist; after
    # the last twist (0.098 s) one at 2.5 periods, then one per period.
    assert fills[0] == pytest.approx(0.083, abs=2e-6)
    assert fills[1] == pytest.approx(0.103, abs=2e-6)
    assert np.diff(fills[1:]) == pytest.approx(np.full(len(fills) - 2, period), abs=2e-6)
