"""The emulated driver's ROS side without a master: rospy's Publisher, Subscriber and Service and actionlib's
server replaced by recorders, on both simulated robots speaking as their drivers (the UR5 as
ur_robot_driver: speed scaling, zeroing, a velocity controller loaded but not started; the Panda as
franka_ros: tf frames, a reflex and its recovery action). The end-to-end run is
tests/robot_packages/test_robot_emulated_drivers.py."""

from __future__ import annotations

import threading
from types import SimpleNamespace
from typing import Any

import numpy as np
import pytest

pytest.importorskip("controller_manager_msgs.srv", reason="needs devel/setup.bash (make test sources it)")

import actionlib
import rospy
from franka_msgs.msg import FrankaState
from mujoco_driver.controllers import STRICT
from mujoco_driver.params import DriverSettings
from mujoco_driver.profiles import load_profile
from mujoco_driver.ros_emulation import EmulatedDriver, resolve_profile
from std_msgs.msg import Float64MultiArray
from trajectory_msgs.msg import JointTrajectory

PROFILE_FOR = {"ur5_custom": "ur_robot_driver", "panda_custom": "franka_ros"}


class _Graph:
    """What was advertised, by name."""

    def __init__(self) -> None:
        self.publishers: dict[str, Any] = {}
        self.subscribers: dict[str, Any] = {}
        self.services: dict[str, Any] = {}
        self.actions: dict[str, Any] = {}


@pytest.fixture
def graph(monkeypatch: pytest.MonkeyPatch) -> _Graph:
    g = _Graph()

    class Publisher:
        def __init__(self, name: str, data_class: type, **kwargs: Any) -> None:
            self.data_class, self.kwargs, self.sent = data_class, kwargs, []
            g.publishers[name] = self

        def publish(self, msg: Any) -> None:
            self.sent.append(msg)

    class Subscriber:
        def __init__(self, name: str, data_class: type, callback: Any, **kwargs: Any) -> None:
            self.data_class, self.callback, self.kwargs = data_class, callback, kwargs
            g.subscribers[name] = self

    class Service:
        def __init__(self, name: str, service_class: type, handler: Any) -> None:
            self.service_class, self.handler = service_class, handler
            g.services[name] = self

    class ActionServer:
        def __init__(self, name: str, action: type, execute_cb: Any, auto_start: bool = True) -> None:
            self.execute, self.started, self.succeeded = execute_cb, auto_start, 0
            g.actions[name] = self

        def start(self) -> None:
            self.started = True

        def set_succeeded(self) -> None:
            self.succeeded += 1

    for name, cls in (("Publisher", Publisher), ("Subscriber", Subscriber), ("Service", Service)):
        monkeypatch.setattr(rospy, name, cls)
    monkeypatch.setattr(actionlib, "SimpleActionServer", ActionServer)
    return g


def _driver(sim, robot, graph: _Graph) -> EmulatedDriver:
    driver = EmulatedDriver(sim, load_profile(PROFILE_FOR[robot.package]), threading.Lock())
    driver.advertise(lambda name, cls: rospy.Publisher(name, cls, queue_size=10, tcp_nodelay=True))
    return driver


def test_each_command_controller_has_its_topic_and_the_callback_learns_its_name(sim, robot, graph):
    driver = EmulatedDriver(sim, load_profile(PROFILE_FOR[robot.package]), threading.Lock())
    got: list[tuple[str, str]] = []
    driver.subscribe_commands(lambda msg, controller: got.append(("trajectory", controller)),
                              lambda msg, controller: got.append(("velocity", controller)))
    topics = {name: sub.data_class for name, sub in graph.subscribers.items()}
    if robot.package == "ur5_custom":
        assert topics == {"scaled_pos_joint_traj_controller/command": JointTrajectory,
                          "joint_group_vel_controller/command": Float64MultiArray}
    else:
        assert topics == {"position_joint_trajectory_controller/command": JointTrajectory,
                          "joint_group_velocity_controller/command": Float64MultiArray}
    for name, sub in graph.subscribers.items():
        assert sub.kwargs == {"queue_size": 1, "tcp_nodelay": True}
        sub.callback(sub.data_class())
        assert got[-1] == ("trajectory" if sub.data_class is JointTrajectory else "velocity", name[:-8])
    assert not graph.publishers and not graph.services  # advertise() comes after the node's own


def test_the_real_drivers_topics_services_and_action_are_advertised(sim, robot, graph):
    _driver(sim, robot, graph)
    cm = ["controller_manager/list_controllers", "controller_manager/switch_controller"]
    if robot.package == "ur5_custom":
        ur = "ur_hardware_interface/"
        assert sorted(graph.publishers) == ["/tf", "speed_scaling_factor", ur + "robot_mode",
                                            ur + "robot_program_running", ur + "safety_mode"]
        assert sorted(graph.services) == [*cm, ur + "dashboard/play", ur + "dashboard/unlock_protective_stop",
                                          ur + "resend_robot_program", ur + "zero_ftsensor"]
        assert [m.mode for m in graph.publishers[ur + "safety_mode"].sent] == [1]  # NORMAL
        assert [m.mode for m in graph.publishers[ur + "robot_mode"].sent] == [7]  # RUNNING
        assert [m.data for m in graph.publishers[ur + "robot_program_running"].sent] == [True]
        assert all(graph.publishers[ur + t].kwargs == {"queue_size": 1, "latch": True}
                   for t in ("safety_mode", "robot_mode", "robot_program_running"))
        assert not graph.actions
    else:
        assert sorted(graph.publishers) == ["/tf", "franka_state_controller/franka_states"]
        assert sorted(graph.services) == cm
        state = graph.publishers["franka_state_controller/franka_states"]
        assert state.data_class is FrankaState and state.kwargs == {"queue_size": 10, "tcp_nodelay": True}
        assert not state.sent  # with each joint state
        assert graph.actions["franka_control/error_recovery"].started


def test_controllers_are_listed_and_switched_through_the_services(sim, robot, graph):
    driver = _driver(sim, robot, graph)
    listed = graph.services["controller_manager/list_controllers"].handler(None).controller
    states = {c.name: c.state for c in listed}
    if robot.package != "ur5_custom":
        assert states == {"franka_state_controller": "running",
                          "position_joint_trajectory_controller": "running",
                          "joint_group_velocity_controller": "initialized"}
        return
    assert states["joint_group_vel_controller"] == "initialized"
    assert "joint_group_vel_controller is initialized" in driver.refusal("joint_group_vel_controller")
    claimed = {c.name: [r.resources for r in c.claimed_resources] for c in listed}
    assert claimed["scaled_pos_joint_traj_controller"] == [list(sim.joint_names)]
    switch = graph.services["controller_manager/switch_controller"].handler
    req = SimpleNamespace(start_controllers=["joint_group_vel_controller"],
                          stop_controllers=["scaled_pos_joint_traj_controller"], strictness=STRICT)
    assert switch(req).ok and driver.refusal("joint_group_vel_controller") == ""
    assert not switch(req).ok  # STRICT: already running, and the other is not
    zero = graph.services["ur_hardware_interface/zero_ftsensor"].handler(None)
    assert zero.success and "zero" in zero.message


def test_the_state_goes_out_with_its_stamp_and_a_reflex_holds_the_arm_until_recovery(sim, robot, graph):
    driver = _driver(sim, robot, graph)
    sim.step(50)
    assert not driver.update(np.asarray(sim.wrench()))
    stamp = rospy.Time(3, 250)
    driver.publish_state(stamp)
    [tf] = graph.publishers["/tf"].sent
    assert tf.transforms and all(t.header.stamp == stamp for t in tf.transforms)
    if robot.package == "ur5_custom":
        assert [m.data for m in graph.publishers["speed_scaling_factor"].sent] == [1.0]
        return
    assert [t.child_frame_id for t in tf.transforms] == ["panda_NE", "panda_EE", "panda_K"]
    states = graph.publishers["franka_state_controller/franka_states"].sent
    [state] = states
    assert state.header.stamp == stamp and state.robot_mode == FrankaState.ROBOT_MODE_MOVE
    np.testing.assert_allclose(state.q, sim.qpos, atol=1e-12)
    np.testing.assert_allclose(state.K_F_ext_hat_K, driver.wrench)
    sim.push([0.0, 0.0, -40.0], duration=0.3)
    tripped = False
    for _ in range(50):
        sim.step(10)
        tripped = driver.update(np.asarray(sim.wrench())) or tripped
    assert tripped
    driver.on_reflex()
    driver.publish_state(rospy.Time(4))
    assert states[-1].robot_mode == FrankaState.ROBOT_MODE_REFLEX
    assert states[-1].current_errors.cartesian_reflex
    assert "franka_control/error_recovery" in driver.refusal("position_joint_trajectory_controller")
    action = graph.actions["franka_control/error_recovery"]
    action.execute(None)
    assert action.succeeded == 1 and driver.refusal("position_joint_trajectory_controller") == ""
    driver.publish_state(rospy.Time(5))
    assert states[-1].robot_mode == FrankaState.ROBOT_MODE_MOVE
    assert not states[-1].current_errors.cartesian_reflex
    assert states[-1].last_motion_errors.cartesian_reflex  # what stopped the last motion


def test_a_protective_stop_holds_the_ur_until_unlocked_after_its_wait_and_the_program_restarted(sim, robot,
                                                                                               graph):
    if robot.package != "ur5_custom":
        pytest.skip("ur_robot_driver's protective stop")
    options = {"protective_stop_force": 30.0, "protective_stop_unlock_after": 0.5}
    profile = load_profile("ur_robot_driver", options)
    driver = EmulatedDriver(sim, profile, threading.Lock())
    driver.advertise(lambda name, cls: rospy.Publisher(name, cls, queue_size=10, tcp_nodelay=True))
    ur = "ur_hardware_interface/"
    safety, running = graph.publishers[ur + "safety_mode"], graph.publishers[ur + "robot_program_running"]
    sim.step(50)
    assert not driver.update(np.asarray(sim.wrench()))
    sim.push([0.0, 0.0, -45.0], duration=0.3)
    for _ in range(30):
        sim.step(10)
        if driver.update(np.asarray(sim.wrench())):
            break
    else:
        pytest.fail("a 45 N push did not trip a 30 N protective stop")
    driver.on_reflex()
    assert safety.sent[-1].mode == 3 and running.sent[-1].data is False  # PROTECTIVE_STOP, program stopped
    refusal = driver.refusal("scaled_pos_joint_traj_controller")
    assert "protective stop: TCP force" in refusal and ur + "dashboard/unlock_protective_stop" in refusal
    unlock = graph.services[ur + "dashboard/unlock_protective_stop"]
    play = graph.services[ur + "dashboard/play"]
    early = play.handler(None)
    assert not early.success and "protective stop" in early.message
    sim.step(int(0.1 / sim.dt))
    answer = unlock.handler(None)  # 0.5 s have not passed yet
    assert not answer.success and "Cannot unlock protective stop" in answer.message
    sim.step(int(0.5 / sim.dt))
    held = sim.qpos.copy()
    assert unlock.handler(None).success and safety.sent[-1].mode == 1
    assert "not running" in driver.refusal("scaled_pos_joint_traj_controller")
    assert graph.services[ur + "resend_robot_program"].handler(None).success and running.sent[-1].data is True
    assert driver.refusal("scaled_pos_joint_traj_controller") == ""
    sim.step(int(0.2 / sim.dt))
    np.testing.assert_allclose(sim.qpos, held, atol=1e-3)  # unlocked and restarted where it was held


def test_the_profile_takes_options_from_the_real_drivers_parameters_unless_the_user_set_them(monkeypatch):
    params = {"franka_state_controller/publish_rate": 100.0}
    monkeypatch.setattr(rospy, "has_param", lambda name: name in params)
    monkeypatch.setattr(rospy, "get_param", lambda name: params[name])
    monkeypatch.setattr(rospy, "resolve_name", lambda name: "/" + name)
    own = DriverSettings.from_params({"scene_config": "s.yaml"})
    assert resolve_profile(own) == (own, None)
    settings, profile = resolve_profile(DriverSettings.from_params({"scene_config": "s.yaml",
                                                                    "profile": "franka_ros"}))
    assert profile is not None and profile.publish_rate == 100.0
    assert (settings.joint_states_topic, settings.wrench_topic, settings.ft_frame) == (
        "franka_state_controller/joint_states", "franka_state_controller/F_ext", "panda_K")
    user = {"scene_config": "s.yaml", "profile": "franka_ros", "profile_options": {"publish_rate": 50.0}}
    _, profile = resolve_profile(DriverSettings.from_params(user))
    assert profile is not None and profile.publish_rate == 50.0
