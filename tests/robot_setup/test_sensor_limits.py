"""`make robot ... DRIVER=<profile>`: the demonstrations' stop-on-contact force derived from the profile's
wrench noise, per variant, as contact_control will measure it (pure, no ROS master)."""

from __future__ import annotations

import math

import pytest
import yaml
from contact_control.noise_floor import NoiseFloor, filtered_fraction
from mujoco_driver.profiles import WrenchSpec, variant_options
from robot_setup.sensor_limits import CAP, MARGIN, contact_force_for, resolvable_force


def test_white_noise_resolves_what_contact_controls_noise_floor_says():
    spec = WrenchSpec("wrench", "ft", "tool0", noise_force=[0.2, 0.4, 0.3])
    floor = NoiseFloor.measure([0.2, 0.4, 0.3, 0.0, 0.0, 0.0], 500.0, 100, 5.0)
    assert resolvable_force(spec, 500.0) == pytest.approx(floor.resolvable(5.0)[0])
    # Slow drift passes the 5 Hz filter almost whole; white noise at 500 Hz keeps 15 % of its std.
    slow = WrenchSpec("wrench", "ft", "tool0", drift_force=0.4, drift_time_constant=1.0)
    assert resolvable_force(slow, 500.0) > 0.9 * 5 * 0.4
    assert resolvable_force(spec, 500.0) == pytest.approx(5 * 0.4 * filtered_fraction(500.0, 5.0))


def _profile(tmp_path, variants) -> str:
    data = {
        "driver": "acme_driver", "publish_rate": 100.0, "joint_states_topic": "joint_states",
        "options": {"sensor": "clean"},
        "variants": {"sensor": variants},
        "wrench": {"topic": "wrench", "frame": "ft", "frame_link": "tool0"},
        "controllers": [{"name": "traj", "type": "t", "command": "trajectory", "initial_state": "running"}],
    }
    path = tmp_path / "acme.yaml"
    path.write_text(yaml.safe_dump(data))
    return str(path)


def test_the_limit_covers_every_variant_up_to_the_cap_and_names_the_others(tmp_path):
    path = _profile(tmp_path, {
        "clean": {},
        "noisy": {"wrench": {"noise_force": 0.5}},       # 5 x 0.5 x 0.33 = 0.83 N at 100 Hz
        "estimate": {"wrench": {"noise_force": 3.6}},    # ~6 N: over the cap
    })
    assert sorted(o["sensor"] for o in variant_options(path)) == ["clean", "estimate", "noisy"]
    force = contact_force_for(path, 0.5)
    resolves = dict(force.variants)
    assert resolves["sensor=clean"] == 0.0
    assert resolves["sensor=noisy"] == pytest.approx(5 * 0.5 * math.sqrt(2 * 1.1107 * 5 / 100), rel=1e-3)
    assert resolves["sensor=estimate"] * MARGIN > CAP and force.cannot == ("sensor=estimate",)
    assert force.limit == 1.5  # 0.83 N x 1.3 = 1.08, rounded up to 0.5 N steps
    assert "sensor=estimate: [CANNOT]" in force.comment()
    # Every variant clean: the thesis's limit.
    assert contact_force_for(_profile(tmp_path, {"clean": {}}), 0.5).limit == 0.5


def test_the_shipped_ur_profile_gives_the_e_series_limit_and_leaves_the_current_estimate_to_cannot():
    force = contact_force_for("ur_robot_driver", 0.5)
    assert force.limit == 1.5 and force.cannot == ("series=cb3_estimate",)
