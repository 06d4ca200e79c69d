"""Named poses: moves within every joint's limits that arrive together; poses checked against the URDF."""

import math
import pathlib

import numpy as np
import pytest
import yaml
from named_poses.poses import NamedPoses, PoseError, UrdfJoint
from named_poses.profile import MotionProfileError, plan_move

SRC = pathlib.Path(__file__).resolve().parents[2] / "src"
ROBOT_PACKAGES = sorted(p for p in SRC.iterdir() if p.name.endswith("_custom"))


def test_move_keeps_each_joint_within_its_limits_and_ends_at_rest_on_the_goal():
    vmax, amax = np.array([0.5, 1.0, 2.0]), np.array([1.0, 4.0, 4.0])
    move = plan_move([0.0, 1.0, -1.0], [1.0, 0.8, 2.0], vmax, amax, sample_period=0.001)
    assert np.allclose(move.positions[-1], [1.0, 0.8, 2.0])
    assert np.allclose(move.velocities[[0, -1]], 0.0)
    assert np.all(np.abs(move.velocities) <= vmax * (1 + 1e-9))
    accel = np.diff(move.velocities, axis=0) / np.diff(move.times)[:, None]
    assert np.all(np.abs(accel) <= amax * 1.01)
    # Straight line in joint space: every joint has covered the same fraction at every instant.
    fraction = (move.positions - move.positions[0]) / (move.positions[-1] - move.positions[0])
    assert np.allclose(fraction, fraction[:, :1])
    # As fast as the slowest joint allows: joint 0 (1 rad at 0.5 rad/s, 1 rad/s^2) takes 1/0.5 + 0.5/1 s.
    assert move.duration == pytest.approx(2.5)


def test_short_move_never_reaches_full_speed():
    move = plan_move([0.0], [0.1], [1.0], [1.0])
    assert move.duration == pytest.approx(2 * math.sqrt(0.1))
    assert np.max(move.velocities) < 1.0


def test_already_there_is_a_zero_length_move():
    assert plan_move([0.3, 0.2], [0.3, 0.2], [1, 1], [1, 1]).duration == 0.0


@pytest.mark.parametrize("bad", [{"max_velocity": [0.0]}, {"goal": [math.nan]}, {"goal": [1.0, 2.0]}])
def test_bad_move_input_is_refused(bad):
    args = {"start": [0.0], "goal": [1.0], "max_velocity": [1.0], "max_acceleration": [1.0]} | bad
    with pytest.raises(MotionProfileError):
        plan_move(**args)


URDF = {
    "a": UrdfJoint("a", False, -1.0, 1.0, 2.0),
    "b": UrdfJoint("b", True, -math.inf, math.inf, 0.3),
}


def test_limits_are_capped_by_the_urdf_and_continuous_joints_take_the_near_turn():
    poses = NamedPoses.from_dict({"poses": {"start": {"a": 0.5, "b": 0.1}}, "max_velocity": 1.0}, URDF)
    assert poses.max_velocity.tolist() == [1.0, 0.3]
    goal = poses.goal("start", [0.0, 2 * math.pi + 0.3])
    assert goal == pytest.approx([0.5, 2 * math.pi + 0.1])


@pytest.mark.parametrize(
    ("data", "named"),
    [
        ({"poses": {"start": {"a": 1.5, "b": 0.0}}}, "poses/start/a: 1.5 rad is outside"),
        ({"poses": {"start": {"a": 0.0, "c": 0.0}}}, "poses/start/c: not a movable joint"),
        ({"poses": {"start": {"a": 0.0, "b": 0.0}, "home": {"a": 0.0}}}, "poses/home: must name the same"),
        ({"poses": {"start": {"a": 0.0, "b": 0.0}}, "max_acceleration": -1}, "max_acceleration"),
        ({"poses": {}}, "poses: expected"),
    ],
)
def test_bad_poses_name_the_key(data, named):
    with pytest.raises(PoseError, match=named):
        NamedPoses.from_dict(data, URDF)


def test_unknown_pose_lists_the_known_ones():
    poses = NamedPoses.from_dict({"poses": {"start": {"a": 0.0, "b": 0.0}}}, URDF)
    with pytest.raises(PoseError, match=r"no named pose 'nap'; known: \['start'\]"):
        poses.goal("nap", [0.0, 0.0])


@pytest.mark.parametrize("package", ROBOT_PACKAGES, ids=lambda p: p.name)
def test_every_robot_package_names_its_scene_start_pose_start(package):
    named = yaml.safe_load((package / "config" / "named_poses.yaml").read_text())
    scene = yaml.safe_load((package / "config" / "sim.yaml").read_text())
    assert named["poses"]["start"] == pytest.approx(scene["start_pose"])
    assert "home" in named["poses"]


def test_node_parameters_refuse_unknown_keys_and_bad_values_naming_the_key():
    from named_poses.params import PARAMETERS, load_settings

    settings = load_settings({"config": "/x/poses.yaml", "trajectory_topic": "t", "goal_tolerance": 0.02})
    assert (settings.config, settings.trajectory_topic) == ("/x/poses.yaml", "t")
    assert settings.goal_tolerance == 0.02
    assert settings.settle_time == PARAMETERS["settle_time"].default == 3.0
    typo = r"^~goal_tolerence is not a parameter: did you mean ~goal_tolerance\?$"
    with pytest.raises(ValueError, match=typo):
        load_settings({"goal_tolerence": 0.1})
    with pytest.raises(ValueError, match=r"^~goal_tolerance: must be > 0, got 0$"):
        load_settings({"goal_tolerance": 0})
    with pytest.raises(ValueError, match="~trajectory_topic: must not be empty"):
        load_settings({"trajectory_topic": ""})


def test_file_limits_default_to_the_declared_parameters():
    from named_poses.params import PARAMETERS

    urdf = {"j": UrdfJoint("j", False, -1.0, 1.0, math.inf)}
    poses = NamedPoses.from_dict({"poses": {"a": {"j": 0.0}}}, urdf)
    assert poses.max_velocity[0] == PARAMETERS["max_velocity"].default
    assert poses.max_acceleration[0] == PARAMETERS["max_acceleration"].default


def test_the_trajectory_controller_is_switched_on_stopping_only_the_ones_on_its_joints():
    from named_poses.switching import Controller, Switch, SwitchError, controller_of, plan_switch

    arm = frozenset({"j1", "j2"})
    listing = [
        Controller("joint_state_controller", "running", frozenset()),
        Controller("scaled_pos_joint_traj_controller", "stopped", arm),
        Controller("joint_group_vel_controller", "running", arm),
        Controller("gripper_controller", "running", frozenset({"finger"})),
    ]
    assert controller_of("scaled_pos_joint_traj_controller/command") == "scaled_pos_joint_traj_controller"
    assert controller_of("/ns/arm_controller/command") == "arm_controller"
    assert controller_of("joint_trajectory") == ""
    switch = plan_switch(listing, "scaled_pos_joint_traj_controller")
    assert switch == Switch(start=("scaled_pos_joint_traj_controller",), stop=("joint_group_vel_controller",))
    assert switch.undo() == Switch(
        start=("joint_group_vel_controller",), stop=("scaled_pos_joint_traj_controller",)
    )
    running = [Controller("arm_controller", "running", arm)]
    assert plan_switch(running, "arm_controller") is None
    with pytest.raises(SwitchError, match=r"'arm_ctrl' is not loaded .*\['arm_controller'\]"):
        plan_switch(running, "arm_ctrl")
