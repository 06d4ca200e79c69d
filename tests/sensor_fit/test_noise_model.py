"""sensor_fit.noise_model (with sensor_fit.rest_windows) on generated recordings: the fit must recover the
stds (15 %), tau (30 %), the rate, the gap, the jump, the rest windows and the offset shift."""

from __future__ import annotations

import math

import numpy as np
import pytest
from sensor_fit.errors import SensorFitError
from sensor_fit.noise_model import fit_axis, fit_recording
from sensor_fit.report import format_report, profile_section, yaml_text
from sensor_fit.results import SensorFit
from sensor_fit_testing import DRIFT, SHIFT, WHITE, Synth


def check_fit(result: SensorFit, data: Synth, axis_tau_tol: float = 0.30) -> None:
    """stds within 15 %, the profile's tau (the median of the force axes') within 30 %, each axis's within
    ``axis_tau_tol``; rate, gap, jump, rest windows and the offset shift."""
    std_tol = 0.15
    assert result.rate == pytest.approx(data.rate, rel=2e-3)
    assert [(g.time, g.length) for g in result.gaps] == [(pytest.approx(data.gap_time, abs=1e-9),
                                                          pytest.approx(data.gap_length, abs=1e-9))]
    for axis, fit in enumerate(result.axes):
        assert fit.white == pytest.approx(WHITE[axis], rel=std_tol), fit
        assert fit.drift == pytest.approx(DRIFT[axis], rel=std_tol), fit
        assert fit.tau == pytest.approx(data.tau, rel=axis_tau_tol), fit
        assert fit.fitted_std == pytest.approx(fit.std, rel=0.1)
    assert result.common_tau == pytest.approx(data.tau, rel=0.30)
    for axis, (white, drift) in enumerate(result.common):
        assert white == pytest.approx(WHITE[axis], rel=std_tol)
        assert drift == pytest.approx(DRIFT[axis], rel=std_tol)
    fz = result.jumps[2]
    assert fz.value == pytest.approx(data.onset_step, abs=2.0)
    assert fz.time == pytest.approx(data.press[0], abs=1.5 / data.rate)
    # Rest windows: the gap splits the first rest; none inside the press; the fit takes the longest.
    windows = result.rest_windows
    assert len(windows) >= 2
    assert windows[0].t0 < 0.1 * data.rest[0][1] and windows[0].t1 <= data.gap_time + 1e-9
    assert windows[-1].t1 == pytest.approx(data.t[-1]) and windows[-1].t0 < data.rest[1][0] + 1.0
    assert all(w.t1 <= data.press[0] or w.t0 >= data.press[1] for w in windows)
    assert result.fit_window == windows[-1]
    shift = result.shift
    assert shift is not None and result.contact
    assert np.allclose(shift.change, SHIFT, atol=[0.1, 0.1, 0.1, 0.005, 0.005, 0.005])
    assert shift.peak == pytest.approx(data.peak, abs=2.0)
    assert data.press[0] < shift.peak_time < data.press[1]
    assert shift.fraction == pytest.approx(np.linalg.norm(SHIFT[:3]) / data.peak, rel=0.06)


def test_fit_recovers_the_model_at_500_hz(fast):
    check_fit(fit_recording(fast.t, fast.w, source="fast"), fast)


def test_fit_recovers_the_model_at_30_hz(slow):
    # 4500 samples, 750 tau: one axis's tau is good to ~17 % rms here, the median of three better.
    check_fit(fit_recording(slow.t, slow.w, source="slow"), slow, axis_tau_tol=0.5)


def test_the_autocovariance_fit_agrees_on_a_long_window(fast):
    result = fit_recording(fast.t, fast.w, method="acf")
    for axis, fit in enumerate(result.axes[:3]):
        assert fit.white == pytest.approx(WHITE[axis], rel=0.15)
        assert fit.drift == pytest.approx(DRIFT[axis], rel=0.15)
        assert fit.tau == pytest.approx(fast.tau, rel=0.4)


def test_given_windows_are_used_in_order(fast):
    result = fit_recording(fast.t, fast.w, rest=[(1.0, 6.0), (-10.0, None)])
    assert result.fit_window.given and result.fit_window.t0 == pytest.approx(1.0, abs=0.01)
    assert result.fit_window.t1 == pytest.approx(6.0, abs=0.01)
    assert result.rest_windows[1].t0 == pytest.approx(fast.t[-1] - 10.0, abs=0.01)
    assert np.allclose(result.shift.change[:3], SHIFT[:3], atol=0.1)
    with pytest.raises(SensorFitError, match="too few samples"):
        fit_recording(fast.t, fast.w, rest=[(3.0, 3.01)])


def test_white_noise_has_no_drift_and_a_short_window_says_so():
    rng = np.random.default_rng(3)
    white = rng.normal(0.0, 0.5, 4000)
    fit = fit_axis(white, 0.002)
    assert fit.tau is None and fit.drift == 0.0 and "no drift seen" in fit.note
    assert fit.white == pytest.approx(0.5, rel=0.05)
    # A drift with tau = 2 s seen through a 1 s window: tau undetermined, the window's share a lower bound.
    n, a = 500, math.exp(-0.002 / 2.0)
    drift = np.empty(n)
    drift[0] = 0.0
    for k in range(1, n):
        drift[k] = a * drift[k - 1] + 0.5 * math.sqrt(1 - a * a) * rng.standard_normal()
    fit = fit_axis(drift + rng.normal(0.0, 0.1, n), 0.002)
    assert fit.tau is None and "window too short" in fit.note
    assert fit.white == pytest.approx(0.1, rel=0.3)
    t = np.arange(n) * 0.002
    result = fit_recording(t, np.column_stack([drift + rng.normal(0.0, 0.1, n)] * 6), rest=[(None, None)])
    assert result.common_tau is None
    section = profile_section(result)
    assert set(section) == {"noise_force", "noise_torque"}
    assert "undetermined" in format_report(result)
    assert "No drift keys" in yaml_text(result, "x.csv")
