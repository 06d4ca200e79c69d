"""Scene settings: validated once, bad values refused naming the key."""

from __future__ import annotations

import copy
import pathlib

import pytest

from mujoco_driver.config import ConfigError, PerJoint, SceneConfig, load_scene_config

ROOT = pathlib.Path(__file__).resolve().parents[2]
GOOD = {
    "timestep": 0.002,
    "start_pose": [0.0, 0.5],
    "servo": {"kp": 100.0, "kv": {"a": 1.0, "b": 2.0}},
    "obstacle": {"position": [0.5, 0.0, 0.1], "size": [0.1, 0.1, 0.2]},
}


@pytest.mark.parametrize("package", ["ur5_custom", "panda_custom"])
def test_robot_packages_scene_files_are_valid(package: str):
    cfg = load_scene_config(str(ROOT / "src" / package / "config" / "sim.yaml"))
    assert cfg.obstacle is not None
    assert cfg.timestep in (0.001, 0.002)
    assert cfg.servo.payload_feedforward


def test_good_config_and_per_joint_forms():
    cfg = SceneConfig.from_dict(GOOD)
    assert cfg.servo.kp.resolve(["a", "b"]) == [100.0, 100.0]
    assert cfg.servo.kv.resolve(["a", "b"]) == [1.0, 2.0]
    assert cfg.start_pose.resolve(["a", "b"]) == [0.0, 0.5]
    assert cfg.obstacle is not None and cfg.obstacle.rpy == (0.0, 0.0, 0.0)


def _with(path: str, value):
    data = copy.deepcopy(GOOD)
    node = data
    keys = path.split(".")
    for key in keys[:-1]:
        node = node.setdefault(key, {})
    if value is KeyError:
        node.pop(keys[-1])
    else:
        node[keys[-1]] = value
    return data


@pytest.mark.parametrize(
    ("path", "value", "message"),
    [
        ("timestep", 0.0, "timestep"),
        ("timestep", "fast", "timestep"),
        ("integrator", "rk4", "integrator"),
        ("integrator", "euler", "integrator"),
        ("start_pose", KeyError, "start_pose"),
        ("servo.kp", -1.0, "servo.kp"),
        ("servo.kp", KeyError, "servo.kp"),
        ("servo.kv", {"a": float("nan")}, "servo.kv.a"),
        ("servo.gain", 1.0, "servo"),
        ("obstacle.size", [0.1, 0.0, 0.1], "obstacle.size[1]"),
        ("obstacle.position", [0.1, 0.2], "obstacle.position"),
        ("table.size", [1.0], "table.size"),
        ("links.tool", "", "links.tool"),
        ("wrench_noise.force_std", -1.0, "wrench_noise.force_std"),
        ("wrench_noise.seed", 1.5, "wrench_noise.seed"),
        ("colour", "red", "colour"),
    ],
)
def test_bad_settings_are_refused_naming_the_key(path, value, message):
    with pytest.raises(ConfigError, match=message.replace("[", r"\[").replace("]", r"\]")):
        SceneConfig.from_dict(_with(path, value))


def test_per_joint_resolution_errors_name_the_joints():
    with pytest.raises(ConfigError, match="missing"):
        PerJoint.parse({"a": 1.0}, "servo.kp").resolve(["a", "b"])
    with pytest.raises(ConfigError, match="unknown"):
        PerJoint.parse({"a": 1.0, "b": 1.0, "c": 1.0}, "servo.kp").resolve(["a", "b"])
    with pytest.raises(ConfigError, match="3 values for 2 joints"):
        PerJoint.parse([1.0, 2.0, 3.0], "start_pose").resolve(["a", "b"])


def test_unreadable_file(tmp_path: pathlib.Path):
    bad = tmp_path / "bad.yaml"
    bad.write_text("servo: [unclosed")
    with pytest.raises(ConfigError, match="cannot read"):
        load_scene_config(str(bad))
    with pytest.raises(ConfigError, match="cannot read"):
        load_scene_config(str(tmp_path / "missing.yaml"))
