"""Settings are validated at start-up, and refusals name the key; the model refuses what it lacks."""

from __future__ import annotations

import pathlib
import re

import numpy as np
import pytest
import yaml
from jog_arm_testing import PANDA, UR5, make_jog

from jog_arm import ArmModel, JogSettings, KinematicsError, SettingsError, StatusCode

ROOT = pathlib.Path(__file__).resolve().parents[2]

MSG_DIR = pathlib.Path(__file__).resolve().parents[2] / "src/majorana/compliant_control_msgs/msg"


def test_defaults_are_valid() -> None:
    settings = JogSettings.from_params({})
    assert settings.hard_stop_singularity_threshold >= settings.singularity_threshold
    assert settings.default_cmd_frame == settings.planning_frame


def test_fork_yaml_layout_is_read() -> None:
    fork_style = {
        "move_group_name": "right_ur5",
        "scale": {"linear": 0.2, "rotational": 0.5},
        "singularity_threshold": 5.5,
        "hard_stop_singularity_threshold": 12.0,
        "pub_period": 0.001,
        "simu": True,
        "cmd_frame": "tool0",
        "joint_limits": {"elbow_joint": {"max_velocity": 1.0, "max_acceleration": 2.0}},
    }
    settings = JogSettings.from_params(fork_style)
    assert (settings.scale_linear, settings.scale_rotational) == (0.2, 0.5)
    assert settings.simu and settings.pub_period == 0.001
    assert settings.default_cmd_frame == "tool0"
    assert settings.joint_limits["elbow_joint"].max_acceleration == 2.0
    flat = JogSettings.from_params({"scale/linear": 0.2})
    assert flat.scale_linear == 0.2


@pytest.mark.parametrize(
    ("params", "key"),
    [
        (
            {"singularity_threshold": 12.0, "hard_stop_singularity_threshold": 7.0},
            "hard_stop_singularity_threshold",
        ),
        ({"low_pass_filter_coeff": 0.5}, "low_pass_filter_coeff"),
        ({"pub_period": 0.0}, "pub_period"),
        ({"pub_period": "fast"}, "pub_period"),
        ({"incoming_cmd_timeout": -1.0}, "incoming_cmd_timeout"),
        ({"scale": {"linear": float("nan")}}, "scale/linear"),
        ({"simu": "yes"}, "simu"),
        ({"command_in_type": "furlongs"}, "command_in_type"),
        ({"command_out_type": "effort"}, "command_out_type"),
        ({"joint_names": ["a", "a"]}, "joint_names"),
        ({"num_outgoing_halt_msgs_to_publish": 0}, "num_outgoing_halt_msgs_to_publish"),
        ({"joint_limits": {"j1": {"max_velocity": -1.0}}}, "joint_limits/j1/max_velocity"),
        ({"joint_limits": {"j1": {"max_jerk": 1.0}}}, "joint_limits/j1"),
        ({"ee_frame_name": ""}, "ee_frame_name"),
        ({"held_joints": [{"head_1_joint": "up"}]}, "held_joints/head_1_joint"),
        ({"held_joints": ["head_1_joint"]}, "held_joints"),
        ({"command_out_type": "velocity_array"}, "integrate_from"),  # commanded: trajectory output only
        ({"clamp_push_force": 2.0}, "clamp_release_force must be below clamp_push_force"),  # 3 N: re-clamps
    ],
    ids=lambda v: v if isinstance(v, str) else None,
)
def test_bad_settings_refused_naming_the_key(params: dict, key: str) -> None:
    with pytest.raises(SettingsError, match=re.escape(f"jog_arm_server/{key}")):
        JogSettings.from_params(params)


@pytest.mark.parametrize("path", sorted(ROOT.glob("src/*_custom/config/jog_arm*.yaml")),
                         ids=lambda p: f"{p.parent.parent.name}/{p.name}")
def test_every_robot_packages_jog_arm_file_loads_over_the_defaults(path: pathlib.Path) -> None:
    """What each robot launch loads (jog_arm's config/jog_arm.yaml, then the package's), whatever launch
    argument selects the file: a refused key stops jog_arm_server on the robot."""
    params = yaml.safe_load((ROOT / "src/jog_arm/config/jog_arm.yaml").read_text())
    params.update(yaml.safe_load(path.read_text()))
    JogSettings.from_params(params)


def test_held_joints_are_a_list_a_later_robot_file_replaces() -> None:
    """`held_joints` is a list of `<joint>: position` (a mapping loaded over another robot's would merge with
    it on the parameter server); jog_arm's own file says `[]`."""
    held = JogSettings.from_params({"held_joints": [{"torso_lift_joint": 0.1}, {"head_1_joint": 0}]})
    assert held.held_joints == {"torso_lift_joint": 0.1, "head_1_joint": 0.0}
    assert JogSettings.from_params({}).held_joints == {}


def test_renamed_keys_warn_and_unknown_keys_refuse_start_up() -> None:
    _, warnings = JogSettings.from_params_with_warnings(
        {"lower_singularity_threshold": 17.0, "publish_period": 0.01, "robot_description": "<robot/>"}
    )
    text = "\n".join(warnings)
    assert "use jog_arm_server/singularity_threshold" in text
    assert "use jog_arm_server/pub_period" in text
    assert "robot_description" not in text
    with pytest.raises(SettingsError, match="jog_arm_server/bogus is not a parameter"):
        JogSettings.from_params_with_warnings({"bogus": 1})
    with pytest.raises(SettingsError, match="did you mean jog_arm_server/incoming_cmd_timeout"):
        JogSettings.from_params({"incoming_cmd_timout": 0.1})


def test_model_locks_joints_that_are_not_controlled() -> None:
    panda = ArmModel(PANDA.urdf, PANDA.tip)  # the chain to the hand: the fingers are locked
    assert panda.joint_names == tuple(f"panda_joint{i}" for i in range(1, 8))
    assert panda.jacobian(np.array(PANDA.start)).shape == (6, 7)
    ur5 = ArmModel(UR5.urdf, UR5.tip)
    assert ur5.jacobian(np.array(UR5.start)).shape == (6, 6)
    # Limits come from the URDF unless overridden.
    assert panda.upper[3] == pytest.approx(-0.0698)
    assert panda.max_velocity[6] == pytest.approx(2.61)


def test_jacobian_matches_forward_kinematics() -> None:
    model = ArmModel(PANDA.urdf, PANDA.tip)
    q = np.array(PANDA.start)
    dq = np.array([0.1, -0.2, 0.3, 0.1, -0.1, 0.2, 0.3])
    h = 1e-6
    p0 = model.frame_pose(q, PANDA.tip).translation
    p1 = model.frame_pose(q + h * dq, PANDA.tip).translation
    np.testing.assert_allclose(model.jacobian(q)[:3] @ dq, (p1 - p0) / h, atol=1e-5)


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"tip_frame": "no_such_link"}, "ee_frame_name 'no_such_link'"),
        ({"tip_frame": "panda_hand", "joint_names": ["panda_joint1", "nope"]}, "joint_names: 'nope'"),
        ({"tip_frame": "panda_link0"}, "is not moved"),
    ],
)
def test_model_refuses_unknown_names(kwargs: dict, message: str) -> None:
    with pytest.raises(KinematicsError, match=re.escape(message)):
        ArmModel(PANDA.urdf, **kwargs)


def test_model_refuses_bad_urdf() -> None:
    with pytest.raises(KinematicsError, match="robot_description"):
        ArmModel("<robot name='broken'><link name='a'/>", "a")


def test_jog_refuses_config_that_does_not_fit_the_model() -> None:
    with pytest.raises(KinematicsError, match="planning_frame"):
        make_jog(UR5, planning_frame="map")
    with pytest.raises(KinematicsError, match="at least 3"):
        make_jog(PANDA, joint_names=["panda_joint1", "panda_joint2"], joint_limits={})
    with pytest.raises(SettingsError, match="nullspace_posture"):
        make_jog(PANDA, nullspace_posture=[0.0, 0.0])
    with pytest.raises(KinematicsError, match="joint_limits/elbow"):
        make_jog(UR5, joint_limits={"elbow": {"max_velocity": 1.0}})


def test_status_codes_match_the_message_definition() -> None:
    text = (MSG_DIR / "JogStatus.msg").read_text()
    constants = {name: int(value) for name, value in re.findall(r"^int8\s+(\w+)\s*=\s*(-?\d+)", text, re.M)}
    assert constants == {code.name: code.value for code in StatusCode}
