"""`make robot ... DRIVER=<profile>`: the hardware files speak the profile's interface (topics, wrench frame,
sign and payload handling, controllers), every name taken from the profile's data; the simulation's files do
not change; a bad profile is refused naming the known ones, before anything is written. No ROS master.

The arm is measured once (the UR3 of example-robot-data, the committed ur3_custom's command); the drivers
are then applied to that plan, as plan_robot does."""

from __future__ import annotations

import dataclasses
import pathlib
import xml.etree.ElementTree as ET

import pytest
import yaml
from jog_arm.robot_stop import parse_robot_stop
from mujoco_driver.profiles import DriverProfile, known_profiles, load_profile
from robot_setup.driver import GENERIC, DriverError, driver_interface
from robot_setup.generate import (
    GeneratorError,
    Plan,
    RobotSpec,
    command_line,
    main,
    plan_robot,
    recorded_command,
    render,
)

UR3 = RobotSpec("ur3", "ur_description/urdf/ur3_robot.urdf", "tool0")
ARGV = ["--name", UR3.name, "--urdf", UR3.urdf, "--tip", UR3.tip]
HARDWARE = {"config/contact_control_hardware.yaml", "config/jog_arm_hardware.yaml", "launch/hardware.launch"}
# What DRIVER may change besides the hardware files: the README (the recorded command, *Real robot*),
# package.xml (the command in its description) and demos.yaml (the contact force with that driver's sensor).
DRIVER_DEPENDENT = HARDWARE | {"README.md", "package.xml", "config/demos.yaml"}


@pytest.fixture(scope="module")
def ur3_plan() -> Plan:
    return plan_robot(UR3, log=lambda _: None)


def _with_driver(plan: Plan, driver: str) -> Plan:
    return dataclasses.replace(plan, spec=dataclasses.replace(plan.spec, driver=driver),
                               driver=driver_interface(driver))


def _hardware(files: dict[str, str]) -> tuple[dict, dict, ET.Element]:
    return (yaml.safe_load(files["config/jog_arm_hardware.yaml"]),
            yaml.safe_load(files["config/contact_control_hardware.yaml"]),
            ET.fromstring(files["launch/hardware.launch"]))


def _named_poses_args(launch: ET.Element) -> dict[str, str]:
    include = next(i for i in launch.iter("include") if "named_poses" in i.get("file", ""))
    return {a.get("name", ""): a.get("value", "") for a in include.iter("arg")}


def _controller(profile: DriverProfile, command: str):
    return next(c for c in profile.controllers if c.command == command)


def test_ur_profile_hardware_files_use_its_topics_frames_and_controllers(ur3_plan):
    profile = load_profile("ur_robot_driver")
    files = render(_with_driver(ur3_plan, "ur_robot_driver"))
    jog, cc, launch = _hardware(files)
    velocity = _controller(profile, "velocity")  # jog_arm's: the driver's velocity controller ...
    assert velocity.initial_state != "running"  # ... which the driver loads without starting it
    running_trajectory = next(c for c in profile.controllers
                              if c.command == "trajectory" and c.initial_state == "running")
    assert jog["joint_topic"] == profile.joint_states_topic
    assert jog["cmd_out_topic"] == f"{velocity.name}/command"
    assert jog["command_out_type"] == "velocity_array"
    assert jog["joint_state_timeout"] == pytest.approx(0.1)  # 12.5 periods at 125 Hz, 0.1 s at least
    assert jog["pub_period"] == pytest.approx(0.004)  # a velocity stream: shorter than the 8 ms of 125 Hz
    assert cc["ft_in_topic"] == profile.wrench.topic
    assert cc["ft_sensor_frame"] == profile.wrench.frame  # tool0_controller, on the driver's tf
    assert profile.wrench.model == "payload_compensated"
    assert (cc["tool_mass"], cc["tool_com"]) == (0, [0.0, 0.0, 0.0])
    assert cc["lp_filter_delta_t"] == pytest.approx(1.0 / profile.publish_rate)
    assert not any(k.startswith("ft_") and k.endswith("_direction") for k in cc)  # sign +1: the defaults
    assert _named_poses_args(launch) == {
        "config": "$(find ur3_custom)/config/named_poses.yaml",
        "trajectory_topic": f"{running_trajectory.name}/command",
        "joint_states_topic": profile.joint_states_topic,
        "output": "$(arg output)",
    }
    assert launch.find(".//remap") is None  # joint_states is robot_state_publisher's own topic
    # The user's switch, in the header and the README: start jog_arm's controller, stop the running one.
    header = files["launch/hardware.launch"]
    assert f"switch {velocity.name} on" in header and f"stopping {running_trajectory.name}" in header
    assert (f'switch_controller "{{start_controllers: [{velocity.name}], stop_controllers: '
            f'[{running_trajectory.name}], strictness: 2}}"') in files["README.md"]
    assert "profile:=ur_robot_driver" in header
    # jog_arm watches the driver's own stops with the profile's names (jog_arm.robot_stop reads them).
    watches, recover = parse_robot_stop(jog["robot_stop"])
    stop = profile.protective_stop
    assert [w.topic for w in watches] == [stop.safety_mode_topic, stop.program_running_topic]
    assert [step.name for step in recover] == [stop.unlock_service, stop.play_services[0]]
    assert "<exec_depend>ur_dashboard_msgs</exec_depend>" in files["package.xml"]


def test_a_franka_profile_watches_its_robot_mode_and_the_generic_driver_nothing(ur3_plan):
    profile = load_profile("franka_ros")
    files = render(_with_driver(ur3_plan, "franka_ros"))
    watches, recover = parse_robot_stop(yaml.safe_load(files["config/jog_arm_hardware.yaml"])["robot_stop"])
    state = profile.reflex.state
    assert [(w.topic, w.type, w.field, w.running) for w in watches] == [
        (state.topic, "franka_msgs/FrankaState", "robot_mode", (1, 2))]
    assert [(s.name, s.action_type) for s in recover] == [
        (profile.reflex.recovery_action, "franka_msgs/ErrorRecoveryAction")]
    assert "<exec_depend>franka_msgs</exec_depend>" in files["package.xml"]
    generic = render(_with_driver(ur3_plan, ""))
    assert "robot_stop" not in yaml.safe_load(generic["config/jog_arm_hardware.yaml"])
    assert "_msgs</exec_depend>" not in generic["package.xml"]


def test_the_driver_changes_only_the_hardware_files_readme_and_package_xml(ur3_plan):
    generic = render(ur3_plan)
    for driver in known_profiles():
        files = render(_with_driver(ur3_plan, driver))
        assert set(files) == set(generic)
        changed = {rel for rel in files if files[rel] != generic[rel]}
        assert changed == DRIVER_DEPENDENT, driver
        assert "written by make robot" in files["launch/hardware.launch"]  # the e2e test finds it so
    assert ur3_plan.driver == GENERIC


def _profile_file(tmp_path: pathlib.Path, **wrench) -> str:
    """A profile of a driver unknown to the code: its own names, one trajectory controller, running."""
    data = {
        "driver": "acme_driver",
        "publish_rate": 50.0,
        "joint_states_topic": "acme/joint_states",
        "wrench": {"topic": "acme/wrench", "frame": "acme_flange", "frame_link": "tool0", **wrench},
        "tf": [{"parent": "base", "child": "acme_flange", "parent_link": "base", "child_link": "tool0"}],
        "controller_manager": "acme/controller_manager",
        "controllers": [
            {"name": "acme_state", "type": "acme/State"},
            {"name": "acme_traj", "type": "acme/Trajectory", "command": "trajectory",
             "initial_state": "running"},
        ],
    }
    path = tmp_path / "acme.yaml"
    path.write_text(yaml.safe_dump(data))
    return str(path)


@pytest.mark.parametrize(("model", "sign", "tool_mass"), [
    ("sensor", 1, 1.0),                 # a raw wrist sensor: contact_control compensates the tool
    ("external_estimate", -1, 0.0),     # net of the configured load, and its reaction (franka's convention)
])
def test_a_profile_path_of_another_driver_sets_its_names_sign_and_payload(ur3_plan, tmp_path, model, sign,
                                                                           tool_mass):
    path = _profile_file(tmp_path, model=model, sign=sign)
    files = render(_with_driver(ur3_plan, path))
    jog, cc, launch = _hardware(files)
    assert jog["joint_topic"] == "acme/joint_states"
    # No velocity controller: jog_arm streams trajectories to the running trajectory controller, no switch.
    assert (jog["cmd_out_topic"], jog["command_out_type"]) == ("acme_traj/command", "trajectory")
    assert jog["joint_state_timeout"] == pytest.approx(0.1)  # 5 periods at 50 Hz
    assert jog["pub_period"] == pytest.approx(0.008)  # trajectories
    assert "switch" not in files["config/jog_arm_hardware.yaml"]
    assert "No controller switch: acme_traj runs from the start." in files["README.md"]
    assert (cc["ft_in_topic"], cc["ft_sensor_frame"]) == ("acme/wrench", "acme_flange")
    assert cc["tool_mass"] == tool_mass
    assert cc["tool_com"] == ([0.0, 0.0, 0.05] if tool_mass else [0.0, 0.0, 0.0])
    directions = [cc.get(f"ft_{axis}_direction", 1) for axis in "xyz"]
    assert directions == [sign] * 3
    assert cc["lp_filter_delta_t"] == pytest.approx(0.02)
    remap = launch.find(".//remap")  # in the robot's <group ns>
    assert remap is not None and remap.attrib == {"from": "joint_states", "to": "acme/joint_states"}
    assert _named_poses_args(launch)["trajectory_topic"] == "acme_traj/command"
    assert _named_poses_args(launch)["joint_states_topic"] == "acme/joint_states"
    assert f"DRIVER={path}" in files["README.md"]


def test_a_slow_driver_gets_a_longer_joint_state_timeout(tmp_path):
    path = _profile_file(tmp_path)
    text = pathlib.Path(path).read_text().replace("publish_rate: 50.0", "publish_rate: 30.0")
    pathlib.Path(path).write_text(text)
    assert driver_interface(path).state_timeout == pytest.approx(0.17)  # 5 periods of 30 Hz, rounded up


def test_a_profile_without_a_trajectory_controller_is_refused(tmp_path):
    path = _profile_file(tmp_path)
    data = yaml.safe_load(pathlib.Path(path).read_text())
    data["controllers"] = [{"name": "acme_vel", "type": "acme/Velocity", "command": "velocity"}]
    pathlib.Path(path).write_text(yaml.safe_dump(data))
    with pytest.raises(DriverError,
                       match=r"needs a controller with `command: trajectory`.*'acme_vel': 'velocity'"):
        driver_interface(path)


def test_a_bad_profile_name_is_refused_naming_the_known_ones_and_nothing_is_written(tmp_path, capsys):
    known = ", ".join(known_profiles())
    assert known == "franka_ros, ur_robot_driver"
    with pytest.raises(GeneratorError, match=rf"DRIVER=ur_robot_drvier: no such mujoco_driver profile; known "
                                             rf"profiles: {known}"):
        plan_robot(dataclasses.replace(UR3, driver="ur_robot_drvier"), log=lambda _: None)
    src = tmp_path / "src"
    src.mkdir()
    assert main([*ARGV, "--driver", "ur_robot_drvier", "--src", str(src)]) == 2
    err = capsys.readouterr().err
    assert err.startswith("make robot: error: DRIVER=ur_robot_drvier: ")
    assert f"known profiles: {known}, or a profile YAML path" in err
    assert list(src.iterdir()) == []


def test_an_invalid_profile_file_is_refused_with_the_loaders_reason(tmp_path):
    path = _profile_file(tmp_path, model="guess")
    with pytest.raises(DriverError, match=rf"DRIVER={path}: invalid mujoco_driver profile: .*wrench.model"):
        driver_interface(path)


def test_a_profile_whose_frames_the_description_lacks_is_refused_and_nothing_is_written(tmp_path, capsys):
    """franka_ros's frames hang on panda_link8: not a UR3's (the emulated driver would refuse to start)."""
    src = tmp_path / "src"
    src.mkdir()
    assert main([*ARGV, "--driver", "franka_ros", "--src", str(src)]) == 2
    err = capsys.readouterr().err
    assert "DRIVER=franka_ros: the profile's frames are not in the ur3 description" in err
    assert "link 'panda_link8'" in err
    assert list(src.iterdir()) == []


def test_the_ur_profiles_frames_are_in_the_ur3_description(ur3_plan):
    """The emulated scene works: base and tool0 (tf base -> tool0_controller) are links of the description."""
    links = {link.get("name") for link in ET.fromstring(ur3_plan.urdf_xml).iter("link")}
    ur = driver_interface("ur_robot_driver")
    assert ur.links == {"base", "tool0"} and ur.missing_links(links) == []
    assert ur.tf == (("base", "tool0_controller"),)


@pytest.mark.parametrize("spec", [
    UR3,
    RobotSpec("ur3", "ur_description/urdf/ur3_robot.urdf", "tool0", driver="ur_robot_driver"),
    RobotSpec("arm", "/some/arm.urdf", "flange", base="base_link", tool_mass=0.5, driver="/x/my_driver.yaml"),
])
def test_the_recorded_command_reads_back(spec):
    assert recorded_command(f"generated by `{command_line(spec)}`: the stock URDF") == spec
    assert recorded_command("a hand-written package") is None
