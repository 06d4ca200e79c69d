"""Laws that stay stable on slow sensors: the gain bound from the sensor's measured rate and the command
latency, and the oscillation watchdog (generated data)."""

import math

import numpy as np
import pytest
from cc_sim import DT, ClosedLoop, controller, laws
from contact_control.axes import END_OSCILLATION, LAW_FOLLOWER, LAW_FORCE_TRACKING, LAW_SPRING
from contact_control.laws import AxisLaw
from contact_control.loop_gain import GainBound, filter_delay

SPRING = AxisLaw(LAW_SPRING, damping=30.0, stiffness=100.0)


def measured(rate: float, **params):
    """A controller that has seen two seconds of wrenches at `rate` Hz (its rate is measured)."""
    ctrl = controller(**params)
    for n in range(int(2 * rate)):
        ctrl.update([0.0] * 6, n / rate, stamp=n / rate)
    return ctrl


def test_the_spring_gain_is_lowered_for_a_30_hz_sensor_and_left_alone_at_500_hz():
    fast = measured(500.0)
    kept, notes = fast.bound_gains(laws(x=SPRING))
    assert kept[0] == SPRING and notes == []
    slow = measured(30.0, command_latency=0.06)
    lowered, notes = slow.bound_gains(laws(x=SPRING, z=SPRING))
    # 0.2 k (0.033 s + 0.06 s) <= 0.5: k <= 26.8 1/s
    assert lowered[0].stiffness == pytest.approx(0.5 / (0.2 * (1 / 30 + 0.06)), rel=0.02)
    assert lowered[2] == lowered[0] and lowered[0].damping == 30.0
    assert "x spring k 100 -> 26.8" in notes[0] and "loop_gain_delay" in notes[-1]
    # Off: unchanged.
    assert measured(30.0, loop_gain_delay=0.0).bound_gains(laws(x=SPRING))[0][0] == SPRING


def test_force_tracking_b_is_raised_only_when_the_surface_stiffness_is_known():
    press = AxisLaw(LAW_FORCE_TRACKING, damping=2000.0, velocity=0.005, target=10.0)
    bound = GainBound(0.5, 0.05, 0.2, 20000.0)
    out, notes = bound.limit(laws(z=press), 1 / 30, 5.0)
    delay = 1 / 30 + 0.05 + filter_delay(5.0)
    assert out[2].damping == pytest.approx(20000.0 * delay / 0.5) and "z force tracking b 2000" in notes[0]
    assert GainBound(0.5, 0.05, 0.2, 0.0).limit(laws(z=press), 1 / 30, 5.0)[0][2] == press
    assert filter_delay(5.0) == pytest.approx(math.sqrt(2) / (2 * math.pi * 5.0))


def test_a_forced_oscillation_halves_the_gain_then_stops_the_axis_with_the_reason():
    loop = ClosedLoop(controller(lp_filter_enabled=False))
    loop.start(laws(z=AxisLaw(LAW_FOLLOWER, damping=30.0)))

    def shaking(t, pose):  # 6 N at 3 Hz: the follower's velocity reverses 6 times a second
        return [0.0, 0.0, 6.0 * math.sin(2 * math.pi * 3.0 * t), 0.0, 0.0, 0.0]

    loop.run(shaking, 1.2)
    assert loop.ctrl.move_active and loop.ctrl.laws[2].damping == 60.0  # halved gain, still running
    assert any("reversed 6 times" in note and "b 30 -> 60" in note for note in loop.ctrl.notes)
    loop.run(shaking, 1.5)
    final = loop.results[-1]
    assert not final.move_active and final.end_conditions[2] == END_OSCILLATION
    assert "axis z" in final.message and "oscillation" in final.message
    assert np.all(loop.velocities()[-100:] == 0.0)  # and it holds still
    assert loop.ctrl.move_outcome(loop.ctrl.move_id) is False


def test_a_steady_push_and_a_push_and_release_are_not_oscillations():
    loop = ClosedLoop(controller())
    loop.start(laws(z=AxisLaw(LAW_FOLLOWER, damping=30.0), x=SPRING))
    loop.run([10.0, 0.0, 6.0, 0.0, 0.0, 0.0], 1.0)
    loop.run([0.0, 0.0, -6.0, 0.0, 0.0, 0.0], 1.0)
    loop.run([0.0] * 6, 1.0)
    assert loop.ctrl.move_active and loop.ctrl.laws[2].damping == 30.0 and loop.ctrl.laws[0] == SPRING


def test_a_resent_request_does_not_undo_the_watchdog():
    loop = ClosedLoop(controller(lp_filter_enabled=False))
    follower = laws(z=AxisLaw(LAW_FOLLOWER, damping=30.0))
    loop.start(follower)
    loop.run(lambda t, pose: [0.0, 0.0, 6.0 * math.sin(2 * math.pi * 3.0 * t), 0.0, 0.0, 0.0], 1.2)
    move = loop.ctrl.move_id
    assert loop.ctrl.set_laws(follower, loop.pose, loop.t) == move  # the same request again: nothing changes
    assert loop.ctrl.laws[2].damping == 60.0
    assert DT > 0


@pytest.mark.parametrize("noise_aware", [True, False])
def test_a_spring_held_against_a_push_on_a_noisy_estimate_is_not_an_oscillation(noise_aware, monkeypatch):
    """Held by a push, the spring's force error crosses zero with the sensor's noise (3.6 N, a current
    estimate): velocity reversals within what that noise gives are not counted (contrast: without that
    floor the watchdog halves the gain on noise, as it did on the emulated CB3)."""
    if not noise_aware:
        monkeypatch.setattr("contact_control.oscillation.WATCH_NOISE_SIGMAS", 0.0)
    rng = np.random.default_rng(4)
    noise = np.array([3.6, 3.6, 3.6, 0.3, 0.3, 0.3])
    loop = ClosedLoop(controller(tare_on_startup=True, lp_filter_delta_t=DT))
    loop.run(lambda t, pose: (rng.normal(size=6) * noise).tolist(), 0.4)  # zeroed: the noise floor
    assert loop.ctrl.intake.noise_floor is not None
    loop.start(laws(x=SPRING))
    loop.run(lambda t, pose: ([8.0, 0, 0, 0, 0, 0] + rng.normal(size=6) * noise).tolist(), 3.0)
    halved = [note for note in loop.ctrl.notes if "gain halved" in note]
    if noise_aware:
        assert loop.ctrl.move_active and loop.ctrl.laws[0] == SPRING and not halved
    else:
        assert halved or not loop.ctrl.move_active
