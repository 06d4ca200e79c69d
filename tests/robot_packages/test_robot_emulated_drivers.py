"""End to end, per robot: the simulated robot speaks as its real driver (mujoco_driver's emulated_robot.launch
with the ur_robot_driver or franka_ros profile), the robot package's hardware.launch runs unchanged on top, as
a user starts it on a real cell, and then (the README's "Real robot" steps):

* UR: jog commands do nothing until joint_group_vel_controller is switched on through the controller manager
  (the running trajectory controller's topic is not jog_arm's); after the switch a twist moves the tool tip;
* Panda: the trajectory controller runs from the start: a twist moves the tool tip;
* both: contact_control's follower, reading the driver's wrench (UR: payload-compensated, in
  tool0_controller; Panda: franka's F_ext estimate, opposite sign, in panda_K, 30 Hz, offset and noise)
  makes the tool give way to a simulated push;
* Panda: a push over the collision threshold trips the reflex: the arm takes no motion until
  franka_control/error_recovery is called.

Every package `make robot` wrote runs the same way against the driver its recorded command names
(`DRIVER=<profile>`: emulated_robot.launch with that profile; none: the generic interface): the controller
switch, when the profile starts jog_arm's controller stopped, takes its names from the profile and the
package's jog_arm_hardware.yaml (a helper shared with the UR5 case).
"""

from __future__ import annotations

import contextlib
import pathlib

import numpy as np
import pytest
import yaml

pytest.importorskip("controller_manager_msgs.srv", reason="needs devel/setup.bash (make test sources it)")

import actionlib
from cartesian_impedance_msgs.msg import ControlLaw
from cartesian_impedance_msgs.srv import ConfigureForceControl, ConfigureForceControlRequest
from compliant_control_msgs.msg import ContactControlStatus
from compliant_control_msgs.srv import MoveToNamedPose, PushEEF, PushEEFRequest
from controller_manager_msgs.srv import ListControllers, SwitchController, SwitchControllerRequest
from franka_msgs.msg import ErrorRecoveryAction, ErrorRecoveryGoal, FrankaState
from geometry_msgs.msg import PoseStamped, TwistStamped, WrenchStamped
from harness.launch import run_launch
from harness.waiting import Collector, wait_until
from mujoco_driver.profiles import DriverProfile, load_profile
from robot_setup.generate import recorded_command
from sensor_msgs.msg import JointState
from std_msgs.msg import Float64
from std_srvs.srv import Trigger

# What a user on the real cell has: the driver's names (from the real drivers' documentation).
CELLS = {
    "ur5_custom": dict(profile="ur_robot_driver", base="base_link", joints="/joint_states", wrench="/wrench",
                       frame="tool0_controller", rate=125.0),
    "panda_custom": dict(profile="franka_ros", base="panda_link0",
                         joints="/franka_state_controller/joint_states",
                         wrench="/franka_state_controller/F_ext", frame="panda_K", rate=30.0),
}


@contextlib.contextmanager
def _cell(robot: str, profile: str, joints: str, hardware_args: dict[str, str] | None = None):
    """The emulated driver first (``profile`` "": the generic interface), then the robot package's
    hardware.launch, unchanged (no arguments but ``hardware_args``, a documented option)."""
    args = {"robot_package": robot, **({"profile": profile} if profile else {})}
    with run_launch("mujoco_driver", "emulated_robot.launch", args=args) as driver:
        driver.wait_for_topic(joints, timeout=40)
        with run_launch(robot, "hardware.launch", args=hardware_args or {}) as stack:
            # named_poses is a node of its own: its service comes up on its own schedule (CI once called
            # move_to before it was advertised: "no provider").
            for service in ("/configure_cartesian_impedance", "/named_poses/move_to"):
                stack.wait_for_service(service, timeout=40)
            stack.wait_for_topic("/contact_control_node/status", timeout=40)
            yield driver, stack
            stack.stop()
            assert stack.proc.returncode == 0, stack.output()[-3000:]
        driver.stop()
        assert driver.proc.returncode == 0, driver.output()[-3000:]


@contextlib.contextmanager
def _clients(rospy):
    """The test's ends: the ground-truth tool tip, contact_control's status, jog_arm's twist input."""
    pose = Collector("/mujoco_driver/eef_pose", PoseStamped)
    cc_status = Collector("/contact_control_node/status", ContactControlStatus)
    twist_pub = rospy.Publisher("/jog_arm_server/delta_jog_cmds", TwistStamped, queue_size=1,
                                tcp_nodelay=True)
    try:
        yield pose, cc_status, twist_pub
    finally:
        pose.close()
        cc_status.close()
        twist_pub.unregister()


def _tip(pose: Collector) -> np.ndarray:
    p = pose.last().pose.position
    return np.array([p.x, p.y, p.z])


def _jog(rospy, twist_pub, pose: Collector, base: str, messages: int | None = None,
         distance: float | None = None, proc=None) -> np.ndarray:
    """Twists of 5 cm/s along -X of the base into jog_arm's input (the keyboard's path) at 50 Hz: a given
    number of them, or until the tip moved ``distance`` [m]. Returns the tip's displacement."""
    start = _tip(pose)
    twist = TwistStamped()
    twist.header.frame_id = base
    twist.twist.linear.x = -0.05
    rate = rospy.Rate(50)
    deadline = rospy.get_time() + 20.0
    sent = 0
    while ((messages is not None and sent < messages)
           or (distance is not None and start[0] - _tip(pose)[0] < distance)):
        assert rospy.get_time() < deadline, f"the tool tip did not move {distance} m along -X"
        assert proc is None or proc.poll() is None, "a launch died"
        twist.header.stamp = rospy.Time.now()
        twist_pub.publish(twist)
        sent += 1
        rate.sleep()  # the sender's rate, not a wait for a result
    return _tip(pose) - start


def _settle(rospy, joints_topic: str) -> None:
    def still() -> bool:
        state = rospy.wait_for_message(joints_topic, JointState, timeout=5)
        return max(abs(v) for v in state.velocity) < 2e-3

    wait_until(still, 10, "the arm to stop")


def _follower_gives_way(rospy, pose: Collector, cc_status: Collector, axis: str, push: float) -> np.ndarray:
    """A follower on ``axis`` (b = 200 N s/m: 5 cm/s for 10 N), a push along it: the tool's displacement."""
    i = "xyz".index(axis)
    req = ConfigureForceControlRequest()
    setattr(req.cart_impedance_params.damping.translational, axis, 200.0)
    getattr(req.direction_control_laws, axis).type = ControlLaw.TYPE_FOLLOWER
    assert rospy.ServiceProxy("/configure_cartesian_impedance", ConfigureForceControl)(req).success
    wait_until(lambda: cc_status.last().move_active, 5, "the follower to be active")
    before = _tip(pose)
    request = PushEEFRequest(duration=0.6)
    setattr(request.wrench.force, axis, push)
    assert rospy.ServiceProxy("/mujoco_driver/push", PushEEF)(request).success
    wait_until(lambda: np.sign(push) * (_tip(pose)[i] - before[i]) > 0.01, 10,
               f"the tool to follow the push along {axis}")
    moved = _tip(pose) - before
    assert rospy.ServiceProxy("/contact_control_node/stop", Trigger)().success
    return moved


def _controller_states(rospy, profile: DriverProfile) -> dict[str, str]:
    list_controllers = rospy.ServiceProxy(f"/{profile.controller_manager}/list_controllers", ListControllers)
    return {c.name: c.state for c in list_controllers().controller}


def _switch_on_jog_controller(rospy, driver, twist_pub, pose: Collector, base: str, robot: str,
                              profile: DriverProfile) -> str:
    """The controller jog_arm commands (its ``cmd_out_topic``, from the package's jog_arm_hardware*.yaml) is
    one of the profile's. If the driver starts it not running, as ur_robot_driver its velocity controller,
    jog_arm's commands are ignored (the arm stays put, the driver names the controller) until the user
    switches it on through controller_manager/switch_controller, stopping the running controllers that command
    the joints (a resource conflict otherwise). Returns what was done, in words."""
    topic = rospy.get_param("/jog_arm_server/cmd_out_topic")  # as hardware.launch loaded it
    name = topic.strip("/").rsplit("/command", 1)[0]
    specs = {c.name: c for c in profile.controllers}
    assert name in specs and specs[name].command != "none", (
        f"jog_arm commands {topic}: not a command controller of {profile.driver}")
    states = _controller_states(rospy, profile)
    assert states == {c.name: c.initial_state for c in profile.controllers}
    if states[name] == "running":
        return f"{name} running from the start"
    ignored = _jog(rospy, twist_pub, pose, base, messages=50, proc=driver.proc)
    assert np.linalg.norm(ignored) < 1e-3, f"a controller that is not running moved the arm: {ignored}"
    assert f"{name} is {states[name]}" in driver.output()
    stop = [c.name for c in profile.controllers if c.command != "none" and states[c.name] == "running"]
    req = SwitchControllerRequest(start_controllers=[name], stop_controllers=stop,
                                  strictness=SwitchControllerRequest.STRICT)
    assert rospy.ServiceProxy(f"/{profile.controller_manager}/switch_controller", SwitchController)(req).ok
    states = _controller_states(rospy, profile)
    assert states[name] == "running" and all(states[c] == "stopped" for c in stop), states
    return f"switched {name} on, stopping {', '.join(stop) or 'nothing'}"


def _named_pose_round_trip(rospy, profile: DriverProfile | None) -> str:
    """`/named_poses/move_to` home and back to start while jog_arm's controller runs: named_poses switches
    its trajectory controller on for each move if it is not running and back afterwards, so the controller
    states are as before (the jog that follows proves jog_arm's controller runs again)."""
    before = _controller_states(rospy, profile) if profile is not None else {}
    move_to = rospy.ServiceProxy("/named_poses/move_to", MoveToNamedPose)
    answers = [move_to(name=name, speed_scale=1.0) for name in ("home", "start")]
    for answer in answers:
        assert answer.success, answer.message
    if profile is not None:
        assert _controller_states(rospy, profile) == before, "named_poses left the controllers switched"
    return "switched" if "switched" in answers[0].message else "no switch"


def _driver_extras(rospy, profile: DriverProfile, wrench: WrenchStamped) -> None:
    """What the profile promises beyond topics: the speed scaling at 1.0, a payload-compensated wrench that
    reads no tool weight at rest, the zero service."""
    if profile.speed_scaling_topic:
        assert rospy.wait_for_message(f"/{profile.speed_scaling_topic}", Float64, timeout=5).data == 1.0
    if profile.wrench.model == "payload_compensated":
        f = wrench.wrench.force
        assert np.linalg.norm([f.x, f.y, f.z]) < 0.5, f"payload not compensated: {f}"
    if profile.wrench.zero_service:
        rospy.wait_for_service(f"/{profile.wrench.zero_service}", timeout=10)
        assert rospy.ServiceProxy(f"/{profile.wrench.zero_service}", Trigger)().success


def _jog_and_push(rospy, robot: str, cell: dict, profile: DriverProfile | None, driver, clients) -> str:
    """The README's *Real robot* steps after the launch: the driver's wrench (frame, rate), the controller
    switch if the profile needs one, a jog of 2 cm along -X that stays on the line, then a follower that gives
    way to pushes along -X and +Y. Returns what was done about controllers, in words."""
    pose, cc_status, twist_pub = clients
    wrench = rospy.wait_for_message(cell["wrench"], WrenchStamped, timeout=10)
    assert wrench.header.frame_id == cell["frame"]
    pose.wait_for(1, timeout=20)
    cc_status.wait_for(1, timeout=20)
    if cell["rate"]:
        # The driver's rate, from the stamps (the real drivers' defaults: CB3 125 Hz, franka 30 Hz).
        wrenches = Collector(cell["wrench"], WrenchStamped)
        wrenches.wait_for(40, timeout=10)
        wrenches.close()
        stamps = np.array([m.header.stamp.to_sec() for m in wrenches.msgs])
        assert np.median(np.diff(stamps)) == pytest.approx(1.0 / cell["rate"], rel=0.15)
    wait_until(lambda: twist_pub.get_num_connections() > 0, 10, "jog_arm to subscribe to its input")
    switched = "generic interface, no controller manager"
    if profile is not None:
        _driver_extras(rospy, profile, wrench)
        switched = _switch_on_jog_controller(rospy, driver, twist_pub, pose, cell["base"], robot, profile)
    named = _named_pose_round_trip(rospy, profile)
    switched += f"; named poses: {named}"
    zeroed = lambda: cc_status.last().safety == ContactControlStatus.SAFETY_OK  # noqa: E731
    wait_until(zeroed, 20, "contact_control to zero the sensor")
    moved = _jog(rospy, twist_pub, pose, cell["base"], distance=0.02, proc=driver.proc)
    assert np.all(np.abs(moved[1:]) < 0.25 * abs(moved[0])), f"tool tip left the X line: {moved}"
    _settle(rospy, cell["joints"])
    _gives_way_on_two_axes(rospy, pose, cc_status, cell["joints"])
    return switched


@pytest.mark.parametrize(("robot", "hardware_args"), [
    ("ur5_custom", {}),
    ("panda_custom", {}),
    # franka_hw's VelocityJointInterface: jog_arm streams to joint_group_velocity_controller, which the user
    # switches on (panda_custom README, "Velocity interface"); named_poses switches its trajectory controller.
    ("panda_custom", {"command_interface": "velocity"}),
])
def test_hardware_launch_runs_unchanged_against_the_emulated_driver(ros_node, robot, hardware_args):
    rospy = ros_node
    cell = CELLS[robot]
    profile = load_profile(cell["profile"])
    with (_cell(robot, cell["profile"], cell["joints"], hardware_args) as (driver, _stack),
          _clients(rospy) as clients):
        switched = _jog_and_push(rospy, robot, cell, profile, driver, clients)
        print(f"\n{robot} as {cell['profile']} {hardware_args} ({switched}): jogged 2 cm along -X; the "
              "follower gave way to 10 N pushes along -X and +Y")
        if profile.reflex is not None and not hardware_args:  # the driver's reflex, whatever the interface
            # Over the collision threshold (franka's 20 N): the reflex stops the arm until error recovery.
            pose, _cc_status, twist_pub = clients
            mode = Collector(f"/{profile.reflex.state.topic}", FrankaState)
            mode.wait_for(1, timeout=5)
            assert mode.last().robot_mode == FrankaState.ROBOT_MODE_MOVE
            push = PushEEFRequest(duration=0.3)
            push.wrench.force.z = -1.5 * profile.reflex.force_thresholds[2]
            assert rospy.ServiceProxy("/mujoco_driver/push", PushEEF)(push).success
            reflex = lambda: mode.last().robot_mode == FrankaState.ROBOT_MODE_REFLEX  # noqa: E731
            wait_until(reflex, 10, "the reflex to trip")
            assert mode.last().current_errors.cartesian_reflex
            _settle(rospy, cell["joints"])
            held = _jog(rospy, twist_pub, pose, cell["base"], messages=50, proc=driver.proc)
            assert np.linalg.norm(held) < 2e-3, f"the arm moved in reflex mode: {held}"
            recovery = actionlib.SimpleActionClient(f"/{profile.reflex.recovery_action}", ErrorRecoveryAction)
            assert recovery.wait_for_server(rospy.Duration(10))
            recovery.send_goal(ErrorRecoveryGoal())
            assert recovery.wait_for_result(rospy.Duration(10))
            move = lambda: mode.last().robot_mode == FrankaState.ROBOT_MODE_MOVE  # noqa: E731
            wait_until(move, 5, "the robot mode back to move")
            # The driver runs again, but jog_arm (robot_stop) holds until asked: jogs still move nothing.
            held = _jog(rospy, twist_pub, pose, cell["base"], messages=25, proc=driver.proc)
            assert np.linalg.norm(held) < 1e-3, f"jog_arm moved the arm before ~recover: {held}"
            answer = rospy.ServiceProxy("/jog_arm_server/recover", Trigger)()
            assert answer.success, answer.message
            _jog(rospy, twist_pub, pose, cell["base"], distance=0.01, proc=driver.proc)
            print(f"{robot}: a {-push.wrench.force.z:g} N push tripped the reflex; after error recovery and "
                  "jog_arm's ~recover the arm jogged again")
            mode.close()


SRC = pathlib.Path(__file__).resolve().parents[2] / "src"
# Packages `make robot` wrote. Their hardware.launch is for the driver their README's `make robot` command
# names (DRIVER=<profile>: that mujoco_driver profile), or without DRIVER for a generic ros_control driver (a
# joint_trajectory_controller on arm_controller/command, joint_states, a WrenchStamped F/T driver on
# `wrench`), which is mujoco_driver's own interface (emulated_robot.launch with no profile).
GENERATED = sorted(
    p.name for p in SRC.glob("*_custom")
    if "written by make robot" in (p / "launch/hardware.launch").read_text()
)


def test_some_robot_packages_are_generated():
    assert GENERATED, "no package written by make robot: the test below would check nothing"


def _gives_way_on_two_axes(rospy, pose: Collector, cc_status: Collector, joints_topic: str) -> None:
    """A 10 N push along -X, then +Y: a sign error on either (franka's F_ext is the reaction) makes the tool
    push back; a frame error moves it off the axis."""
    for axis, push in (("x", -10.0), ("y", 10.0)):
        moved = _follower_gives_way(rospy, pose, cc_status, axis, push)
        _settle(rospy, joints_topic)
        i = "xyz".index(axis)
        others = np.delete(np.abs(moved), i)
        assert np.all(others < 0.25 * abs(moved[i])), f"the follower left the {axis} axis: {moved}"


def _generated_cell(robot: str) -> tuple[dict, DriverProfile | None]:
    """What a user of a generated package has: the driver its recorded `make robot` command names, with
    that profile's names (none: the generic interface), and the base frame of its jog_arm config."""
    spec = recorded_command((SRC / robot / "README.md").read_text())
    assert spec is not None, f"{robot}: written by make robot, but its README records no command"
    base = yaml.safe_load((SRC / robot / "config/jog_arm_hardware.yaml").read_text())["planning_frame"]
    if not spec.driver:
        return dict(profile="", base=base, joints="/joint_states", wrench="/wrench", frame="ft_sensor",
                    rate=None), None
    profile = load_profile(spec.driver)
    cell = dict(profile=spec.driver, base=base, joints=f"/{profile.joint_states_topic}",
                wrench=f"/{profile.wrench.topic}", frame=profile.wrench.frame, rate=profile.publish_rate)
    return cell, profile


@pytest.mark.parametrize("robot", GENERATED)
def test_a_generated_hardware_launch_runs_unchanged_against_its_driver(ros_node, robot):
    """What a user of a new arm gets from `make robot [DRIVER=...]`: hardware.launch, with no argument, on
    the driver it was written for (emulated with the recorded profile, or the generic interface): after the
    controller switch the profile needs, a jog moves the tool tip along the line, a follower gives way to
    pushes on two axes."""
    rospy = ros_node
    cell, profile = _generated_cell(robot)
    with _cell(robot, cell["profile"], cell["joints"]) as (driver, _stack), _clients(rospy) as clients:
        switched = _jog_and_push(rospy, robot, cell, profile, driver, clients)
        on = cell["profile"] or "the generic driver"
        print(f"\n{robot}: generated hardware.launch on {on} ({switched}): jogged 2 cm along -X; the "
              "follower gave way to 10 N pushes along -X and +Y")
