"""bias_map: the fit recovers a known load error and a smooth offset; the file round-trips; the predictor
is the map."""

from __future__ import annotations

import numpy as np
import pytest
from cc_sim import rot
from contact_control.bias_map import BiasMapError, MapSample, fit_bias_map, load_bias_map

NAMES = ("j1", "j2", "j3", "j4", "j5", "j6")
G = np.array([0.0, 0.0, -9.81])
DM, COM = 0.3, np.array([0.01, -0.02, 0.05])  # a payload set 0.3 kg too light, its COM off


def orientation(q: np.ndarray) -> np.ndarray:
    """A wrist-like orientation that is a smooth function of the joints (tool down at q = 0)."""
    return (rot((0, 0, 1), q[0]) @ rot((0, 1, 0), q[1] + q[2] + q[3]) @ rot((1, 0, 0), q[4])
            @ rot((0, 0, 1), q[5]) @ rot((1, 0, 0), np.pi))


def smooth_offset(q: np.ndarray, amplitude: float = 1.5) -> np.ndarray:
    """An offset like the emulated drivers' (mujoco_driver's WrenchModel): a sine over the joints."""
    rng = np.random.default_rng(7)
    directions = rng.normal(size=(6, len(q)))
    directions *= 0.5 / np.linalg.norm(directions, axis=1, keepdims=True)
    phases = rng.uniform(0.0, 2 * np.pi, 6)
    return np.array([amplitude] * 3 + [amplitude / 10] * 3) * np.sin(directions @ q + phases)


def reading(q: np.ndarray, noise: float = 0.0, rng: np.random.Generator | None = None) -> MapSample:
    u = orientation(q).T @ G
    force = DM * u
    w = np.concatenate([force, np.cross(COM, force)]) + smooth_offset(q) + np.array([2.0, -1.0, 0.5, 0, 0, 0])
    if noise:
        assert rng is not None
        w = w + rng.normal(0.0, noise, 6) * np.array([1, 1, 1, 0.01, 0.01, 0.01])
    return MapSample(tuple(q), tuple(u), tuple(w))  # type: ignore[arg-type]


def sweep(count: int, seed: int = 1, span: float = 0.4) -> list[np.ndarray]:
    rng = np.random.default_rng(seed)
    return [rng.uniform(-span, span, 6) for _ in range(count)]


def test_a_known_load_error_and_smooth_offset_are_recovered_on_held_out_poses() -> None:
    rng = np.random.default_rng(3)
    fitted = fit_bias_map(NAMES, [reading(q, 0.05, rng) for q in sweep(60)])
    assert fitted.mass == pytest.approx(DM, rel=0.1)
    assert np.linalg.norm(np.array(fitted.moment) / fitted.mass - COM) < 0.1 * np.linalg.norm(COM) + 0.002
    # On poses it never saw (same workspace), it predicts the offset's change within 10 % of its size.
    test_poses = sweep(40, seed=99, span=0.35)
    q0 = np.zeros(6)
    truth = np.array([np.array(reading(q).wrench) - reading(q0).wrench for q in test_poses])
    pred = np.array([np.array(fitted.predict(q, reading(q).gravity)) - fitted.predict(q0, reading(q0).gravity)
                     for q in test_poses])
    err = np.abs(pred - truth)[:, :3]
    size = np.abs(truth[:, :3]).max()
    assert size > 1.5, "the test's offset must move by newtons over the sweep"
    assert err.max() < 0.1 * size, f"largest error {err.max():.3f} N of a {size:.2f} N change"
    assert fitted.residual_force < 0.15, fitted.describe()  # the held-out std: noise plus what is left


def test_the_held_out_std_tells_an_offset_the_map_cannot_follow() -> None:
    """A bumpy offset (frequency 20 x the smooth one) is not a low-order polynomial: the map says so."""
    rng = np.random.default_rng(5)
    samples = []
    for q in sweep(60):
        s = reading(q)
        bump = 1.0 * np.sin(10.0 * q[0]) * np.cos(8.0 * q[2])
        samples.append(MapSample(s.q, s.gravity, (s.wrench[0] + bump, *s.wrench[1:])))
    del rng
    assert fit_bias_map(NAMES, samples).held_out_std[0] > 0.3


def test_the_file_round_trips_and_the_predictor_reorders_and_clamps(tmp_path) -> None:
    fitted = fit_bias_map(NAMES, [reading(q) for q in sweep(60)], frame="tool0_controller", command="x")
    path = tmp_path / "map.yaml"
    path.write_text(fitted.to_yaml())
    loaded = load_bias_map(str(path))
    assert loaded.frame == "tool0_controller" and loaded.joint_names == NAMES
    q = np.array([0.1, -0.2, 0.3, 0.0, 0.2, -0.1])
    u = reading(q).gravity
    assert np.allclose(loaded.predict(q, u), fitted.predict(q, u), atol=1e-3)
    # A joint state with other joints and another order.
    names = ("gripper", *reversed(NAMES))
    predictor = loaded.predictor(names)
    state = [0.5, *reversed(q.tolist())]
    assert np.allclose(predictor(state), loaded.predictor(NAMES)(q), atol=1e-9)
    # Far outside the sweep the prediction stays what it is at the sweep's edge.
    far = q.copy()
    far[0] = 3.0
    edge = q.copy()
    edge[0] = loaded.upper[0]
    assert np.allclose(loaded.predictor(NAMES)(far), loaded.predictor(NAMES)(edge))


def test_bad_input_is_refused_with_the_reason(tmp_path) -> None:
    with pytest.raises(BiasMapError, match="10 or more poses"):
        fit_bias_map(NAMES, [reading(q) for q in sweep(5)])
    level = [MapSample(tuple(q), (0.0, 0.0, -9.81), reading(q).wrench) for q in sweep(30)]
    with pytest.raises(BiasMapError, match="tilt the tool"):
        fit_bias_map(NAMES, level)
    fitted = fit_bias_map(NAMES, [reading(q) for q in sweep(30)])
    with pytest.raises(BiasMapError, match="no joint"):
        fitted.predictor(NAMES[:5])
    bad = tmp_path / "bad.yaml"
    bad.write_text(fitted.to_yaml().replace("held_out_std:", "held_out_sdt:"))
    with pytest.raises(BiasMapError, match="held_out_std"):
        load_bias_map(str(bad))
    with pytest.raises(BiasMapError, match="No such file"):
        load_bias_map(str(tmp_path / "none.yaml"))


def test_the_maps_error_leaves_out_the_noise_of_the_held_out_readings() -> None:
    """Readings with 0.3 N of noise each: what is left on held-out poses is mostly their noise, which the
    noise floor counts already; the map's own error (what contact_control adds to its floor) is far less."""
    rng = np.random.default_rng(8)
    noisy = fit_bias_map(NAMES, [reading(q, 0.3, rng) for q in sweep(60)])
    assert noisy.held_out_std[0] > 0.2
    assert noisy.residual_force < 0.6 * min(noisy.held_out_std[:3]), noisy.describe()
