"""Rate-true preprocessing: the filter's cutoff in Hz and the stale timeout hold at the sensor's real rate."""

import math

import numpy as np
import pytest
from cc_sim import controller, laws
from contact_control.axes import LAW_FOLLOWER, SAFETY_STALE
from contact_control.laws import AxisLaw
from contact_control.rate import SamplePeriod

RATES = [30.0, 92.0, 125.0, 500.0, 1000.0]  # franka F_ext default, a Panda recording, UR CB3, e-Series, ATI


def filtered_amplitude(rate: float, freq: float, adapt: bool = True, seconds: float = 6.0) -> float:
    """Amplitude of the preprocessed Z force for a 10 N sine of `freq` Hz sampled at `rate` Hz, after the
    filter settled; the controller is configured for 500 Hz (lp_filter_delta_t 0.002) with a 5 Hz cutoff."""
    ctrl = controller(lp_filter_delta_t=0.002, lp_filter_cutoff_freq=5.0, lp_filter_rate_adapt=adapt,
                      force_deadband=0.0)
    out = []
    n = round(seconds * rate)
    for k in range(n):
        t = k / rate
        f = 10.0 * math.sin(2 * math.pi * freq * t)
        result = ctrl.update([0.0, 0.0, f, 0.0, 0.0, 0.0], t, stamp=t)
        if t > seconds / 2:
            out.append(result.wrench[2])
    return (max(out) - min(out)) / 2


@pytest.mark.parametrize("rate", RATES)
def test_the_cutoff_stays_in_hz_whatever_the_sensor_rate(rate):
    assert filtered_amplitude(rate, 0.5) == pytest.approx(10.0, rel=0.03)  # passband
    assert filtered_amplitude(rate, 5.0) == pytest.approx(10.0 / math.sqrt(2), rel=0.08)  # -3 dB at 5 Hz


def test_without_adaptation_the_cutoff_moves_with_the_rate_as_in_the_fork():
    # Designed for 500 Hz, fed at 92 Hz: the 5 Hz cutoff acts as 0.92 Hz, so 5 Hz is almost gone.
    assert filtered_amplitude(92.0, 5.0, adapt=False) < 0.2 * filtered_amplitude(92.0, 5.0)


@pytest.mark.parametrize("rate", RATES)
def test_the_stale_timeout_is_ten_periods_with_a_floor(rate):
    ctrl = controller(wrench_timeout=0.1, wrench_timeout_periods=10)
    for k in range(100):
        ctrl.update([0.0] * 6, k / rate, stamp=k / rate)
    assert ctrl.intake.sample_period == pytest.approx(1.0 / rate)
    assert ctrl.intake.wrench_timeout == pytest.approx(max(0.1, 10.0 / rate))


def test_a_212_ms_dropout_at_92_hz_halts_a_follower_and_data_resumes_it():
    ctrl = controller(wrench_timeout=0.1, lp_filter_delta_t=0.002)
    ctrl.set_laws(laws(z=AxisLaw(LAW_FOLLOWER, damping=30.0)), np.eye(4), 0.0)
    t = 0.0
    for _ in range(200):
        t += 1 / 92
        ctrl.update([0.0, 0.0, 8.0, 0.0, 0.0, 0.0], t, stamp=t)
    assert ctrl.last_result.velocity[2] > 0.1
    held = ctrl.check_stale(t + 0.15)  # 0.15 s into a 0.212 s dropout
    assert held is not None and held.safety == SAFETY_STALE and held.velocity[2] == 0.0
    t += 0.212
    assert ctrl.update([0.0, 0.0, 8.0, 0.0, 0.0, 0.0], t, stamp=t).safety == 0
    assert ctrl.move_active


def test_the_measured_rate_is_reported_once_with_the_configured_one():
    ctrl = controller(lp_filter_delta_t=0.002)
    for k in range(200):
        ctrl.update([0.0] * 6, k / 92, stamp=k / 92)
    assert len(ctrl.notes) == 1
    assert "92 Hz" in ctrl.notes[0] and "lp_filter_delta_t says 0.002 s" in ctrl.notes[0]


def test_a_follower_on_92_hz_data_does_not_move_against_the_force():
    """A hand pushing up and down (0.7 Hz, +-8 N, noise): a follower should move with the force. With the
    filter designed for the wrong rate it lags and moves against the push for a while at every reversal."""

    def against(adapt: bool) -> int:
        rng = np.random.default_rng(3)
        ctrl = controller(lp_filter_delta_t=0.002, lp_filter_cutoff_freq=5.0, lp_filter_rate_adapt=adapt)
        ctrl.set_laws(laws(z=AxisLaw(LAW_FOLLOWER, damping=30.0)), np.eye(4), 0.0)
        count = 0
        for k in range(1380):  # 15 s at 92 Hz
            t = k / 92
            force = 8.0 * math.sin(2 * math.pi * 0.7 * t)
            v = ctrl.update([0.0, 0.0, force + rng.normal(0, 0.3), 0, 0, 0], t, stamp=t).velocity[2]
            if v * force < 0.0 and abs(force) > 3.0:  # moving against a push the hand clearly feels
                count += 1
        return count

    assert against(adapt=True) == 0
    assert against(adapt=False) > 20


def test_sample_period_ignores_dropouts_repeats_and_jumps():
    period = SamplePeriod(window=8)
    times = [k * 0.01 for k in range(5)] + [0.04, 1.0] + [1.0 + k * 0.01 for k in range(1, 10)]
    changes = [period.add(t) for t in times]
    assert period.period == pytest.approx(0.01)
    assert sum(changes) == 1


def test_a_bursty_publisher_is_measured_at_its_mean_rate_and_one_stall_changes_nothing():
    """A starved process publishing a 500 Hz sensor in bursts (stamped at publish time): the median interval
    read 168-370 Hz under CI's load and redesigned the filter each window; the mean does not move."""
    period = SamplePeriod(window=32)
    t, times = 0.0, []
    for _burst in range(40):  # 10 samples 0.1 ms apart, then the 19.1 ms the process was away: 500 Hz
        times += [t + k * 0.0001 for k in range(10)]
        t += 0.02
    seen = [period.period for x in times if period.add(x)]
    # Within the 10 % that makes contact_control redesign its filter (a window holds 3.2 bursts: the phase
    # counts); the median said 0.1 ms.
    assert seen and all(p == pytest.approx(0.002, rel=0.1) for p in seen), seen
    steady = period.period
    stalled = [t + k * 0.002 for k in range(16)] + [t + 0.1 + k * 0.002 for k in range(16)]  # a 70 ms stall
    assert not any(period.add(x) for x in stalled)
    assert period.period == steady
    later = stalled[-1] + 0.002
    for k in range(96):  # a sensor that really changed rate (to 100 Hz) is taken after two windows of it
        period.add(later + k * 0.01)
    assert period.period == pytest.approx(0.01)
