"""Contact control that knows its sensor: the noise floor measured while zeroing, the deadbands and the
smallest force limits derived from it, and force limits that one spike does not end (generated data)."""

import numpy as np
import pytest
from cc_sim import DT, ClosedLoop, laws
from contact_control.axes import END_FT_VIOLATION, END_NONE, LAW_COMPLIANT_MOVE, LAW_FOLLOWER, SAFETY_OK
from contact_control.drift import ZeroDrift
from contact_control.laws import AxisLaw
from contact_control.noise_floor import NoiseFloor, filtered_fraction
from contact_control.request import SET_CONTROL_FORCE_FAILED, RequestError

from contact_control import ContactControl, load_settings

NOISE = np.array([0.41, 0.63, 0.18, 0.01, 0.01, 0.005])  # UR e-series at rest (500 Hz), N and Nm


def zeroed(noise=NOISE, rate=500.0, seed=1, **params):
    """A controller zeroed on `rate` Hz samples of white noise around an offset; returns it and the noise."""
    ctrl = ContactControl(load_settings({"lp_filter_delta_t": 1.0 / rate, **params}))
    rng = np.random.default_rng(seed)
    offset = np.array([3.0, 3.2, -18.0, 0.1, 0.2, 0.0])
    t = 0.0
    for _ in range(10000):
        if not ctrl.intake.zeroing:
            return ctrl, rng, offset, t
        ctrl.update((offset + rng.normal(size=6) * noise).tolist(), t, stamp=t)
        t += 1.0 / rate
    raise AssertionError(f"never zeroed: {ctrl.last_result.message}")


def test_the_noise_floor_is_measured_while_zeroing_and_reported():
    ctrl, _, _, t = zeroed()
    floor = ctrl.intake.noise_floor
    assert floor is not None and floor.rate == pytest.approx(500.0)
    assert floor.samples >= 100 and t == pytest.approx(0.2, abs=0.01)  # 0.2 s window at 500 Hz
    np.testing.assert_allclose(floor.std, NOISE, rtol=0.2)
    # After the 5 Hz filter, white noise at 500 Hz keeps sqrt(2 * 1.11 * 5 / 500) = 0.149 of its std.
    np.testing.assert_allclose(np.array(floor.filtered) / floor.std, 0.149, rtol=0.01)
    assert any("noise floor at rest" in note and "refused" in note for note in ctrl.notes)


def test_a_slow_sensor_is_zeroed_over_enough_samples_to_measure_its_noise():
    ctrl, _, _, t = zeroed(noise=NOISE * 0.5, rate=30.0)
    # 25 samples, not the 6 of 0.2 s
    assert ctrl.intake.noise_floor.samples == 25 and t == pytest.approx(25 / 30.0, abs=0.04)
    assert filtered_fraction(30.0, 5.0) == pytest.approx(np.sqrt(2 * 1.1107 * 5 / 30), rel=1e-3)


def test_a_force_limit_below_what_the_sensor_resolves_is_refused_with_the_reason_and_changes_nothing():
    ctrl, *_ = zeroed()
    force, _ = ctrl.intake.resolvable()
    assert force == pytest.approx(5 * 0.63 * 0.149, rel=0.2)  # 5 filtered stds of the worst axis: ~0.47 N
    running = ctrl.set_laws(laws(x=AxisLaw(LAW_FOLLOWER, damping=30.0)), np.eye(4), 1.0)
    with pytest.raises(RequestError) as err:
        ctrl.set_laws(laws(z=AxisLaw(LAW_COMPLIANT_MOVE, velocity=-0.01, force_limit=0.2)), np.eye(4), 1.0)
    assert err.value.code == SET_CONTROL_FORCE_FAILED and err.value.axis == "z"
    assert "below what the sensor resolves" in err.value.message and f"{force:.3g} N" in err.value.message
    assert ctrl.move_id == running and ctrl.move_active and ctrl.laws[0].law == LAW_FOLLOWER
    ctrl.set_laws(laws(z=AxisLaw(LAW_COMPLIANT_MOVE, velocity=-0.01, force_limit=1.0)), np.eye(4), 1.0)
    # Without the check (noise_limit_sigmas 0) the same request is accepted, as before.
    ctrl, *_ = zeroed(noise_limit_sigmas=0.0)
    ctrl.set_laws(laws(z=AxisLaw(LAW_COMPLIANT_MOVE, velocity=-0.01, force_limit=0.2)), np.eye(4), 1.0)


def test_the_deadband_follows_the_noise_so_a_follower_on_a_noisy_sensor_holds_still():
    noise = np.array([2.0, 2.0, 2.0, 0.05, 0.05, 0.05])  # a current-based estimate, 500 Hz
    follower = AxisLaw(LAW_FOLLOWER, damping=30.0)
    travel = {}
    for sigmas in (4.0, 0.0):
        ctrl, rng, offset, t = zeroed(noise=noise, noise_deadband_sigmas=sigmas, follower_deadband_force=0.0,
                                      min_velocity_linear=0.0, tare_max_force_spread=20.0,
                                      oscillation_reversals=0)
        ctrl.set_laws(laws(x=follower, y=follower, z=follower), np.eye(4), t)
        v = []
        for n in range(1000):
            r = ctrl.update((offset + rng.normal(size=6) * noise).tolist(), t + n * DT, stamp=t + n * DT)
            v.append(r.velocity[:3])
        travel[sigmas] = np.abs(np.sum(v, axis=0) * DT).max()
    # 2 s of 2 N noise (filtered std 0.3 N): the follower with the noise deadband moves a few millimetres
    # (38 mm without: it wanders)
    assert travel[4.0] < 0.004 and travel[0.0] > 10 * travel[4.0]
    # and a real push still moves it
    r = ctrl.update((offset + np.array([10.0, 0, 0, 0, 0, 0])).tolist(), t + 2.1, stamp=t + 2.1)
    assert r.safety == SAFETY_OK


def test_one_spike_over_the_limit_does_not_end_a_compliant_move_but_a_contact_does():
    loop = ClosedLoop(ContactControl(load_settings({"tare_on_startup": False, "lp_filter_enabled": False})))
    loop.start(laws(z=AxisLaw(LAW_COMPLIANT_MOVE, velocity=-0.01, force_limit=2.0)))
    loop.run([0.0] * 6, 0.6)  # past force_limit_arm_time

    def spike(t, pose):
        return [0.0, 0.0, 5.0 if abs(t - 0.7) < DT / 2 else 0.0, 0.0, 0.0, 0.0]

    loop.run(spike, 0.2)
    assert loop.results[-1].move_active
    loop.run([0.0, 0.0, 3.0, 0.0, 0.0, 0.0], 0.1)  # contact: 3 N on every sample
    final = loop.results[-1]
    assert not final.move_active and final.end_conditions[2] == END_FT_VIOLATION
    assert final.end_conditions[:2] == [END_NONE, END_NONE]
    # With force_limit_samples 1 (the fork) the same spike ends it.
    loop = ClosedLoop(ContactControl(load_settings({"tare_on_startup": False, "lp_filter_enabled": False,
                                                    "force_limit_samples": 1})))
    loop.start(laws(z=AxisLaw(LAW_COMPLIANT_MOVE, velocity=-0.01, force_limit=2.0)))
    loop.run([0.0] * 6, 0.6)
    loop.run(spike, 0.2)
    assert not loop.results[-1].move_active


def test_noise_floor_limits_take_the_worst_axis():
    floor = NoiseFloor.measure([0.1, 0.3, 0.2, 0.01, 0.02, 0.03], 100.0, 50, None)
    assert floor.filtered == floor.std  # no filter
    assert floor.resolvable(5.0) == pytest.approx((1.5, 0.15))


def test_slow_noise_passes_the_filter_so_it_counts_whole():
    # The Panda's F_ext at rest (92 Hz bag, fitted with fit_sensor): lag-1 0.97 on fz, almost all of it passes
    # a 5 Hz filter; white noise at 92 Hz keeps sqrt(2 * 1.11 * 5 / 92) = 0.35 of its std.
    assert filtered_fraction(92.0, 5.0, 0.97) > 0.9
    assert filtered_fraction(92.0, 5.0, 0.0) == pytest.approx(0.347, abs=0.005)
    rate, a = 92.0, 0.95
    rng = np.random.default_rng(2)
    x = np.zeros(6)
    ctrl = ContactControl(load_settings({"lp_filter_delta_t": 1.0 / rate}))
    t = 0.0
    while ctrl.intake.zeroing and t < 5.0:
        x = a * x + np.sqrt(1 - a * a) * np.array([0.3, 0.3, 0.3, 0.03, 0.03, 0.03]) * rng.normal(size=6)
        ctrl.update(x.tolist(), t, stamp=t)
        t += 1.0 / rate
    floor = ctrl.intake.noise_floor
    assert floor is not None
    assert np.all(np.array(floor.filtered) > 0.6 * np.array(floor.std))  # not the white-noise 0.35


def test_the_zero_drift_is_measured_at_rest_and_re_tared_by_the_policy():
    for limit, retared in ((0.0, False), (2.0, True)):
        ctrl, rng, offset, t = zeroed(auto_tare_drift=limit)
        assert ctrl.intake.zero_drift is None
        moved = offset + np.array([3.0, -1.0, 2.0, 0.0, 0.0, 0.0])  # the zero moved 3.7 N (after a press)
        for n in range(400):  # 0.8 s at 500 Hz: not yet a whole 1 s window
            ctrl.update((moved + rng.normal(size=6) * NOISE).tolist(), t + n * 0.002, stamp=t + n * 0.002)
        assert ctrl.intake.zero_drift is None
        for n in range(400, 1200):
            r = ctrl.update((moved + rng.normal(size=6) * NOISE).tolist(), t + n * 0.002, stamp=t + n * 0.002)
        drift = np.array(ctrl.intake.zero_drift)
        if retared:
            np.testing.assert_allclose(drift[:3], 0.0, atol=0.3)  # re-tared: the next window reads ~0
            assert any("re-tared at rest: the zero had moved by 3." in note for note in ctrl.notes)  # 3.7 N
            assert max(abs(f) for f in r.wrench[:3]) < 0.5
        else:
            np.testing.assert_allclose(drift[:3], [3.0, -1.0, 2.0], atol=0.15)
            assert abs(r.wrench[0] - 3.0) < 0.5  # still there: the laws would feel 3 N
    # A law running: no drift measured meanwhile (the arm is not at rest).
    ctrl, rng, offset, t = zeroed()
    ctrl.set_laws(laws(z=AxisLaw(LAW_FOLLOWER, damping=30.0)), np.eye(4), t)
    for n in range(1000):
        ctrl.update((offset + rng.normal(size=6) * NOISE).tolist(), t + n * 0.002, stamp=t + n * 0.002)
    assert ctrl.intake.zero_drift is None


CURRENT_ESTIMATE = np.array([3.6, 3.6, 3.6, 0.3, 0.3, 0.3])  # a CB3's wrench from joint currents at 125 Hz


def test_a_current_estimate_is_zeroed_with_spread_limits_from_its_own_noise():
    ctrl, _, offset, _ = zeroed(noise=CURRENT_ESTIMATE, rate=125.0)
    floor = ctrl.intake.noise_floor
    np.testing.assert_allclose(floor.std, CURRENT_ESTIMATE, rtol=0.4)
    # The mean of the window's samples, not one of them: within 3 stds of a mean of >= 25 samples.
    assert np.all(np.abs(np.array(ctrl.preprocessor.bias) - offset) < 3 * CURRENT_ESTIMATE / 5)
    force, _ = ctrl.intake.resolvable()
    assert force > 3.0  # a 0.5 N stop is refused on this sensor (runner's [CANNOT]), not left to noise
    # The fixed 4 N spread limit alone (the old rule): the window restarts on noise for ever.
    with pytest.raises(AssertionError, match=r"never zeroed.*4 N"):
        zeroed(noise=CURRENT_ESTIMATE, rate=125.0, tare_spread_sigmas=0.0)


def test_a_touch_among_the_first_samples_of_a_window_still_restarts_it():
    """The first samples are checked together (median-based std, which a touch in a few does not inflate):
    a 5 N touch in the first 10 of a clean sensor's samples restarts the window, as it did one by one."""
    ctrl = ContactControl(load_settings({"lp_filter_delta_t": 0.002}))
    rng = np.random.default_rng(3)
    offset = np.array([1.0, -2.0, 5.0, 0.0, 0.0, 0.0])
    touch = np.array([0.0, 0.0, 5.0, 0.0, 0.0, 0.0])
    messages = []
    for n in range(300):
        w = offset + (touch if n < 10 else 0.0) + rng.normal(size=6) * 0.05
        messages.append(ctrl.update(w.tolist(), n * 0.002, stamp=n * 0.002).message)
    assert not ctrl.intake.zeroing
    assert any("changed by 5." in m and "tare_max_force_spread 4 N" in m for m in messages)
    np.testing.assert_allclose(ctrl.preprocessor.bias, offset, atol=0.03)


def test_a_tare_on_request_is_a_steady_window_again_and_giving_up_keeps_the_bias():
    ctrl, rng, offset, t = zeroed()
    old = ctrl.preprocessor.bias
    moved = offset + np.array([2.0, 0.0, -1.0, 0.0, 0.0, 0.0])

    def feed(n):
        nonlocal t
        out = []
        for _ in range(n):
            t += 0.002
            out.append(ctrl.update((moved + rng.normal(size=6) * NOISE).tolist(), t, stamp=t))
        return out

    ctrl.set_laws(laws(x=AxisLaw(LAW_FOLLOWER, damping=30.0)), np.eye(4), t)
    ctrl.intake.start_zeroing()
    held = feed(50)  # 0.1 s of a 0.2 s window: the follower holds still, the bias is the old one
    assert ctrl.intake.zeroing and all(r.velocity == [0.0] * 6 for r in held)
    assert ctrl.preprocessor.bias == old
    feed(60)
    assert not ctrl.intake.zeroing and ctrl.move_active  # the move goes on with the new zero
    np.testing.assert_allclose(ctrl.preprocessor.bias[:3], moved[:3], atol=0.15)
    assert ctrl.intake.noise_floor.samples >= 100
    new = ctrl.preprocessor.bias
    ctrl.intake.start_zeroing()
    feed(10)
    assert "keep the tool free" in ctrl.intake.cancel_zeroing()
    assert not ctrl.intake.zeroing and ctrl.preprocessor.bias == new  # given up: nothing changed


def test_the_drift_of_a_noisy_estimate_is_measured_within_its_noise():
    ctrl, rng, offset, t = zeroed(noise=CURRENT_ESTIMATE, rate=125.0)
    moved = offset + np.array([10.0, 0.0, 0.0, 0.0, 0.0, 0.0])
    for n in range(1, 400):  # 3.2 s at 125 Hz
        ctrl.update((moved + rng.normal(size=6) * CURRENT_ESTIMATE).tolist(), t + n / 125, stamp=t + n / 125)
    assert ctrl.intake.zero_drift is not None and abs(ctrl.intake.zero_drift[0] - 10.0) < 2.5
    # Without the noise floor the watch's fixed 4 N spread never sees a steady second on this sensor.
    watch = ZeroDrift(1.0, 4.0, 0.4, spread_sigmas=8.0)
    bias = offset.tolist()
    samples = (moved + rng.normal(size=(200, 6)) * CURRENT_ESTIMATE).tolist()
    assert all(watch.add(w, bias, k / 50) is None for k, w in enumerate(samples))
    watch.noise = tuple(CURRENT_ESTIMATE)
    watch.restart()
    assert any(watch.add(w, bias, k / 50) is not None for k, w in enumerate(samples))


def test_the_offset_moving_with_the_pose_raises_the_smallest_limit_and_says_so(tmp_path):
    """A declared pose-dependent offset (no map) or a bias map's held-out residual counts beside the noise:
    a limit the noise alone would allow is refused over the move, with that reason."""
    plain, *_ = zeroed()
    noise_only, _ = plain.intake.resolvable()
    ctrl, *_ = zeroed(pose_offset_force=0.3)
    force, _ = ctrl.intake.resolvable()
    assert force == pytest.approx(np.hypot(noise_only, 5 * 0.3), rel=1e-6)  # 5 sigmas: ~1.57 N
    plain.set_laws(laws(z=AxisLaw(LAW_COMPLIANT_MOVE, velocity=-0.01, force_limit=1.0)), np.eye(4), 1.0)
    with pytest.raises(RequestError) as err:
        ctrl.set_laws(laws(z=AxisLaw(LAW_COMPLIANT_MOVE, velocity=-0.01, force_limit=1.0)), np.eye(4), 1.0)
    message = err.value.message
    assert "offset's change with the pose 0.3 N" in message and f"{force:.3g} N" in message
