"""Wrench preprocessing: tool gravity after tare, frames with lever arm, sign flips, deadband, bad data."""

import math

import numpy as np
import pytest
from cc_sim import controller, laws, rot
from contact_control.axes import LAW_FOLLOWER, SAFETY_NAN, SAFETY_OK, SAFETY_OVER_LIMIT, SAFETY_ZEROING
from contact_control.laws import AxisLaw
from contact_control.params import load_settings
from contact_control.preprocess import PreprocessError, WrenchPreprocessor

G = np.array([0.0, 0.0, -9.81])
MASS, COM = 1.3, np.array([0.01, -0.02, 0.08])  # kg, m (sensor frame)
OFFSET = np.array([1.5, -0.7, 3.2, 0.05, -0.12, 0.03])  # the sensor's own zero error [N, Nm]
R_TARE = rot([0, 0, 1], 0.5) @ rot([1, 0, 0], 0.3)  # tared while a little tilted


def sensor_reading(R_world_sensor, external=(0.0,) * 6):
    """What the sensor reads: offset + tool weight at this orientation + external wrench (sensor frame)."""
    f = R_world_sensor.T @ (MASS * G)
    return OFFSET + np.concatenate([f, np.cross(COM, f)]) + np.asarray(external)


REORIENTED = [  # 90 degrees about each horizontal axis of the fixed frame, both ways, and upside down
    ("+90 about X", rot([1, 0, 0], math.pi / 2) @ R_TARE),
    ("-90 about X", rot([1, 0, 0], -math.pi / 2) @ R_TARE),
    ("+90 about Y", rot([0, 1, 0], math.pi / 2) @ R_TARE),
    ("-90 about Y", rot([0, 1, 0], -math.pi / 2) @ R_TARE),
    ("180 about X", rot([1, 0, 0], math.pi) @ R_TARE),
]


@pytest.mark.parametrize(("name", "R"), REORIENTED)
def test_tool_gravity_stays_compensated_after_reorienting(name, R):
    ctrl = controller(
        tool_mass=MASS, tool_com=COM.tolist(), follower_deadband_force=0.3, follower_deadband_torque=0.03
    )
    ctrl.intake.tare(sensor_reading(R_TARE).tolist(), R_TARE)
    ctrl.set_laws([AxisLaw(LAW_FOLLOWER, damping=30.0)] * 3 + [AxisLaw(LAW_FOLLOWER, damping=3.0)] * 3)
    for n in range(50):
        result = ctrl.update(sensor_reading(R).tolist(), n * 0.002, R_world_sensor=R)
    assert result.safety == SAFETY_OK
    assert np.abs(result.wrench[:3]).max() < 0.2
    assert np.abs(result.wrench[3:]).max() < 0.02
    assert result.velocity == [0.0] * 6  # a follower on every axis stays still


@pytest.mark.parametrize(("name", "R"), REORIENTED)
def test_without_tool_model_the_same_motion_reads_a_large_force(name, R):
    # The contrast that shows the test above can fail: tare alone absorbs the weight at one orientation only.
    ctrl = controller(follower_deadband_force=0.3)
    ctrl.intake.tare(sensor_reading(R_TARE).tolist(), R_TARE)
    ctrl.update(sensor_reading(R).tolist(), 0.0, R_world_sensor=R)
    result = ctrl.update(sensor_reading(R).tolist(), 0.002, R_world_sensor=R)
    # Upside down the error is twice the weight (25.5 N) and trips the 25 N global limit instead (on the
    # second wrench: force_limit_samples).
    assert np.abs(result.wrench[:3]).max() > 5.0 or result.safety == SAFETY_OVER_LIMIT


def test_external_push_survives_compensation():
    pre = WrenchPreprocessor(
        load_settings({"tool_mass": MASS, "tool_com": COM.tolist(), "lp_filter_enabled": False})
    )
    pre.tare(sensor_reading(R_TARE).tolist(), R_TARE)
    R = REORIENTED[0][1]
    push = np.array([0.0, 4.0, -2.0, 0.1, 0.0, 0.0])
    code, w = pre.process(sensor_reading(R, push).tolist(), None, R)
    assert code == SAFETY_OK
    assert w == pytest.approx(push.tolist(), abs=1e-9)


def test_gravity_needs_the_orientation():
    pre = WrenchPreprocessor(load_settings({"tool_mass": 1.0}))
    with pytest.raises(PreprocessError):
        pre.process([0.0] * 6, None, None)


FRAMES = [  # (sensor pose in the control frame: rotation, position), sensor wrench, control wrench
    ((np.eye(3), [0, 0, 0]), [1, 2, 3, 0.1, 0.2, 0.3], [1, 2, 3, 0.1, 0.2, 0.3]),
    # Sensor 0.1 m above the control origin: a force along X gives a torque about Y (p x F).
    ((np.eye(3), [0, 0, 0.1]), [10, 0, 0, 0, 0, 0], [10, 0, 0, 0, 1.0, 0]),
    ((np.eye(3), [0.2, 0, 0]), [0, 0, -5, 0, 0, 0], [0, 0, -5, 0, 1.0, 0]),
    # Sensor rotated 90 degrees about Z: its X is the control Y.
    ((rot([0, 0, 1], math.pi / 2), [0, 0, 0]), [3, 0, 0, 0.5, 0, 0], [0, 3, 0, 0, 0.5, 0]),
    # Sensor upside down (180 about X) and offset along Y.
    ((rot([1, 0, 0], math.pi), [0, 0.1, 0]), [0, 0, 2, 0, 0, 0], [0, 0, -2, -0.2, 0, 0]),
]


@pytest.mark.parametrize(("pose", "sensor", "control"), FRAMES)
def test_frame_change_includes_the_lever_arm(pose, sensor, control):
    T = np.eye(4)
    T[:3, :3], T[:3, 3] = pose
    pre = WrenchPreprocessor(load_settings({"lp_filter_enabled": False}))
    code, w = pre.process(sensor, T)
    assert code == SAFETY_OK
    assert w == pytest.approx(control, abs=1e-12)



@pytest.mark.parametrize(("pose", "sensor", "control"), FRAMES)
def test_the_fast_wrench_is_the_unfiltered_one_in_the_control_frame(pose, sensor, control):
    # What force tracking's pressing guard reads: the sample before the low-pass, moved to the control frame
    # like the filtered one, no deadband; the filtered result has barely started to move.
    T = np.eye(4)
    T[:3, :3], T[:3, 3] = pose
    pre = WrenchPreprocessor(load_settings({"force_deadband": 5.0}))
    pre.keep_fast = True
    pre.process([0.0] * 6, T)  # the filter starts from its first sample: at rest, then the step
    code, w = pre.process(sensor, T)
    assert code == SAFETY_OK
    assert pre.fast == pytest.approx(control, abs=1e-12)
    assert max(abs(v) for v in w) < 0.1 * max(abs(v) for v in control)

def test_sign_flags_flip_force_and_torque_of_their_axis():
    pre = WrenchPreprocessor(
        load_settings({"lp_filter_enabled": False, "ft_x_direction": -1, "ft_z_direction": -1})
    )
    assert pre.process([1, 2, 3, 4, 5, 6])[1] == [-1, 2, -3, -4, 5, -6]


def test_deadband_zeroes_small_components_only():
    pre = WrenchPreprocessor(
        load_settings({"lp_filter_enabled": False, "force_deadband": 1.0, "torque_deadband": 0.1})
    )
    assert pre.process([0.9, -1.5, -0.99, 0.05, 0.2, -0.09])[1] == [0.0, -1.5, 0.0, 0.0, 0.2, 0.0]


@pytest.mark.parametrize("bad", [math.nan, math.inf, -math.inf])
@pytest.mark.parametrize("index", range(6))
def test_non_finite_wrench_is_flagged_and_leaves_the_filter_alone(bad, index):
    pre = WrenchPreprocessor(load_settings({}))
    good = [1.0, 0.0, 0.0, 0.0, 0.0, 0.0]
    pre.process(good)
    w = list(good)
    w[index] = bad
    assert pre.process(w) == (SAFETY_NAN, None)
    assert pre.process(good)[1] == pytest.approx(good)  # filter state not poisoned


@pytest.mark.parametrize(
    ("wrench", "code"),
    [
        ([15, 15, 15, 0, 0, 0], SAFETY_OVER_LIMIT),  # |F| = 26 N > 25 N though each component is below
        ([14, 14, 14, 0, 0, 0], SAFETY_OK),
        ([0, 0, 0, 0, 0, 26], SAFETY_OVER_LIMIT),
    ],
)
def test_global_limits_use_the_magnitude(wrench, code):
    assert WrenchPreprocessor(load_settings({})).process(wrench)[0] == code


def test_tare_refuses_invalid_data_and_keeps_the_bias():
    pre = WrenchPreprocessor(load_settings({}))
    pre.tare([1, 2, 3, 4, 5, 6])
    with pytest.raises(PreprocessError):
        pre.tare([math.nan, 0, 0, 0, 0, 0])
    assert pre.bias == (1, 2, 3, 4, 5, 6)


def test_startup_tare_window_0_zeroes_the_first_valid_wrench():
    ctrl = controller(tare_on_startup=True, tare_window=0.0)
    ctrl.update([math.nan] * 6, 0.0)  # an invalid first sample is not used
    ctrl.set_laws(laws(z=AxisLaw(LAW_FOLLOWER, damping=30.0)))
    assert ctrl.update([0.5, 0.0, 7.0, 0.0, 0.0, 0.0], 0.002).wrench == pytest.approx([0.0] * 6)
    assert ctrl.update([0.5, 0.0, 17.0, 0.0, 0.0, 0.0], 0.004).wrench[2] > 0.0


def _run(ctrl, samples, t0=0.0, period=0.002):
    """Feeds wrenches at 500 Hz; the results."""
    return [ctrl.update(list(w), t0 + k * period) for k, w in enumerate(samples)]


def test_startup_zeroing_holds_still_over_the_window_then_zeroes_the_mean():
    ctrl = controller(tare_on_startup=True, lp_filter_enabled=False)
    ctrl.set_laws(laws(z=AxisLaw(LAW_FOLLOWER, damping=30.0)))  # set before any data: waits
    rng = np.random.default_rng(7)
    noisy = [OFFSET + rng.normal(0.0, 0.4, 6) * [1, 1, 1, 0.02, 0.02, 0.02] for _ in range(150)]
    out = _run(ctrl, noisy)
    zeroing = [r for r in out if r.safety == SAFETY_ZEROING]
    assert 95 <= len(zeroing) <= 101, "held for the 0.2 s window at 500 Hz"
    assert all(r.velocity == [0.0] * 6 for r in zeroing)
    assert "keep the tool free" in zeroing[0].message
    assert out[-1].safety == SAFETY_OK
    # The mean of 100 samples: the bias is within 0.15 N of the offset (one sample: 0.4 N noise).
    assert np.max(np.abs(np.array(ctrl.preprocessor.bias[:3]) - OFFSET[:3])) < 0.15
    assert any("sensor zeroed over 0.2 s" in note for note in ctrl.notes)


def test_a_touch_that_ends_during_zeroing_is_not_taken_as_the_zero():
    """The start-up race seen in the simulation: a push present at the first wrench, released soon after.
    Tared on that first sample, the follower drove the tool the other way (down into the block) once the
    push ended; the window restarts instead, and the follower stays put."""
    ctrl = controller(tare_on_startup=True, lp_filter_enabled=False)
    ctrl.set_laws(laws(z=AxisLaw(LAW_FOLLOWER, damping=30.0)))
    pushed = [OFFSET + np.array([0, 0, 5.0, 0, 0, 0])] * 50  # 0.1 s of a 5 N push, then the free sensor
    out = _run(ctrl, pushed + [OFFSET] * 300)
    restarted = [r for r in out if "changed by 5.00 N" in r.message]
    assert restarted and restarted[0].safety == SAFETY_ZEROING
    assert "tare_max_force_spread 4 N" in restarted[0].message
    assert ctrl.preprocessor.bias == pytest.approx(tuple(OFFSET))
    assert all(abs(r.velocity[2]) < 1e-9 for r in out), "the follower never moved"
    up = OFFSET + np.array([0, 0, 6.0, 0, 0, 0])
    assert _run(ctrl, [up] * 5, t0=1.0)[-1].velocity[2] > 0.0, "then follows a push up"
