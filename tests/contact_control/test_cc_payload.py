"""Payload identification: mass, centre of mass and sensor bias from wrenches at a few static orientations."""

import math

import numpy as np
import pytest
from cc_sim import rot
from contact_control.payload import PayloadError, fit_payload, gravity_in_sensor, read_csv_samples
from contact_control.preprocess import WrenchPreprocessor

from contact_control import load_settings

TOOL = {"tool_mass": 1.3, "tool_com": [0.01, -0.02, 0.06]}
BIAS = [2.0, -1.5, 4.0, 0.1, -0.2, 0.05]
# Tool pointing down, then tilted 0.5 rad about X, -X, Y, -Y and X+Y (a robot-agnostic identify plan).
DOWN = rot((1, 0, 0), math.pi)
TILTS = [
    (None, 0.0), ((1, 0, 0), 0.5), ((1, 0, 0), -0.5), ((0, 1, 0), 0.5), ((0, 1, 0), -0.5), ((1, 1, 0), 0.5),
]


def readings(noise: float = 0.0, tilts=TILTS, seed: int = 1):
    """What a sensor carrying TOOL with offset BIAS reads at each orientation (the preprocessor's model)."""
    rng = np.random.default_rng(seed)
    model = WrenchPreprocessor(load_settings({**TOOL, "lp_filter_enabled": False}))
    samples = []
    for axis, angle in tilts:
        R = DOWN if axis is None else rot(axis, angle) @ DOWN
        w = np.asarray(model.gravity_wrench(R)) + BIAS + rng.normal(0.0, noise, 6)
        samples.append((gravity_in_sensor(R), w))
    return samples


def test_six_orientations_give_back_the_tool_and_the_bias():
    fit = fit_payload(readings())
    assert fit.mass == pytest.approx(1.3, abs=1e-9)
    assert fit.com == pytest.approx((0.01, -0.02, 0.06), abs=1e-9)
    assert fit.bias == pytest.approx(BIAS, abs=1e-9)
    assert fit.force_rms < 1e-9 and fit.condition < 100


def test_with_sensor_noise_the_tool_is_within_5_percent_and_5_mm():
    samples = [s for seed in range(20) for s in readings(noise=0.05, seed=seed)]  # averaging noisy readings
    fit = fit_payload(samples)
    assert fit.mass == pytest.approx(1.3, rel=0.05)
    assert np.linalg.norm(np.asarray(fit.com) - TOOL["tool_com"]) < 0.005
    assert 0.02 < fit.force_rms < 0.1  # the noise shows in the residual
    assert fit.yaml_keys().startswith("tool_mass: 1.29") and "\nbias: [" in fit.yaml_keys()


def test_too_few_or_too_alike_orientations_are_refused_with_a_reason():
    with pytest.raises(PayloadError, match="3 or more"):
        fit_payload(readings()[:2])
    same = readings(tilts=[(None, 0.0)] * 4)
    with pytest.raises(PayloadError, match="separate mass"):
        fit_payload(same)
    two = readings(tilts=[(None, 0.0), ((1, 0, 0), 0.5)] * 2)
    with pytest.raises(PayloadError, match="centre of mass"):
        fit_payload(two)


def test_a_sensor_reading_the_opposite_sign_is_named():
    flipped = [(u, -np.asarray(w)) for u, w in readings()]
    with pytest.raises(PayloadError, match="not positive"):
        fit_payload(flipped)


def test_csv_with_rotations_or_gravity_columns(tmp_path):
    rotations = tmp_path / "rot.csv"
    lines = ["fx,fy,fz,tx,ty,tz," + ",".join(f"r{i}{j}" for i in (1, 2, 3) for j in (1, 2, 3))]
    gravity = tmp_path / "grav.csv"
    glines = ["fx, fy, fz, tx, ty, tz, gx, gy, gz"]
    model = WrenchPreprocessor(load_settings({**TOOL, "lp_filter_enabled": False}))
    for axis, angle in TILTS:
        R = DOWN if axis is None else rot(axis, angle) @ DOWN
        w = np.asarray(model.gravity_wrench(R)) + BIAS
        lines.append(",".join(map(str, [*w, *R.ravel()])))
        glines.append(", ".join(map(str, [*w, *gravity_in_sensor(R)])))
    rotations.write_text("\n".join(lines) + "\n")
    gravity.write_text("\n".join(glines) + "\n")
    for path in (rotations, gravity):
        assert fit_payload(read_csv_samples(str(path))).mass == pytest.approx(1.3)
    bad = tmp_path / "bad.csv"
    bad.write_text("fx,fy,fz\n1,2,3\n")
    with pytest.raises(PayloadError, match="tx"):
        read_csv_samples(str(bad))
