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
"""

from __future__ import annotations

import contextlib
import pathlib

import numpy as np
import pytest

pytest.importorskip("controller_manager_msgs.srv", reason="needs devel/setup.bash (make test sources it)")

import actionlib
from cartesian_impedance_msgs.msg import ControlLaw
from cartesian_impedance_msgs.srv import ConfigureForceControl, ConfigureForceControlRequest
from compliant_control_msgs.msg import ContactControlStatus
from compliant_control_msgs.srv import PushEEF, PushEEFRequest
from controller_manager_msgs.srv import ListControllers, SwitchController, SwitchControllerRequest
from driver_emulation_msgs.msg import ErrorRecoveryAction, ErrorRecoveryGoal
from geometry_msgs.msg import PoseStamped, TwistStamped, WrenchStamped
from harness.launch import run_launch
from harness.waiting import Collector, wait_until
from sensor_msgs.msg import JointState
from std_msgs.msg import Float64, String
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
def _cell(robot: str):
    """Emulated driver first, then the robot package's hardware.launch, unchanged (no arguments)."""
    cell = CELLS[robot]
    with run_launch("mujoco_driver", "emulated_robot.launch",
                    args={"robot_package": robot, "profile": cell["profile"]}) as driver:
        driver.wait_for_topic(cell["joints"], timeout=40)
        with run_launch(robot, "hardware.launch") as stack:
            stack.wait_for_service("/configure_cartesian_impedance", timeout=40)
            stack.wait_for_topic("/contact_control_node/status", timeout=40)
            yield driver, stack
            stack.stop()
            assert stack.proc.returncode == 0, stack.output()[-3000:]
        driver.stop()
        assert driver.proc.returncode == 0, driver.output()[-3000:]


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


@pytest.mark.parametrize("robot", ["ur5_custom", "panda_custom"])
def test_hardware_launch_runs_unchanged_against_the_emulated_driver(ros_node, robot):
    rospy = ros_node
    cell = CELLS[robot]
    with _cell(robot) as (driver, _stack):
        wrench = rospy.wait_for_message(cell["wrench"], WrenchStamped, timeout=10)
        assert wrench.header.frame_id == cell["frame"]
        pose = Collector("/mujoco_driver/eef_pose", PoseStamped)
        cc_status = Collector("/contact_control_node/status", ContactControlStatus)
        twist_pub = rospy.Publisher("/jog_arm_server/delta_jog_cmds", TwistStamped, queue_size=1,
                                    tcp_nodelay=True)
        try:
            pose.wait_for(1, timeout=20)
            cc_status.wait_for(1, timeout=20)
            # The driver's rate, from the stamps (the real drivers' defaults: CB3 125 Hz, franka 30 Hz).
            wrenches = Collector(cell["wrench"], WrenchStamped)
            wrenches.wait_for(40, timeout=10)
            wrenches.close()
            stamps = np.array([m.header.stamp.to_sec() for m in wrenches.msgs])
            assert np.median(np.diff(stamps)) == pytest.approx(1.0 / cell["rate"], rel=0.15)
            wait_until(lambda: twist_pub.get_num_connections() > 0, 10, "jog_arm to subscribe to its input")
            list_controllers = rospy.ServiceProxy("/controller_manager/list_controllers", ListControllers)
            states = {c.name: c.state for c in list_controllers().controller}

            if robot == "ur5_custom":
                # The real UR's defaults: 125 Hz, the wrench already without the tool's weight.
                assert rospy.wait_for_message("/speed_scaling_factor", Float64, timeout=5).data == 1.0
                f = wrench.wrench.force
                assert np.linalg.norm([f.x, f.y, f.z]) < 0.5, f"payload not compensated: {f}"
                assert rospy.ServiceProxy("/ur_hardware_interface/zero_ftsensor", Trigger)().success
                assert states["scaled_pos_joint_traj_controller"] == "running"
                assert states["joint_group_vel_controller"] == "initialized"
                # jog_arm's velocity commands go to a controller that is not running: the arm stays put.
                ignored = _jog(rospy, twist_pub, pose, cell["base"], messages=50, proc=driver.proc)
                assert np.linalg.norm(ignored) < 1e-3, f"a stopped controller moved the arm: {ignored}"
                assert "joint_group_vel_controller is initialized" in driver.output()
                req = SwitchControllerRequest(start_controllers=["joint_group_vel_controller"],
                                              stop_controllers=["scaled_pos_joint_traj_controller"],
                                              strictness=SwitchControllerRequest.STRICT)
                assert rospy.ServiceProxy("/controller_manager/switch_controller", SwitchController)(req).ok
                states = {c.name: c.state for c in list_controllers().controller}
                assert states["joint_group_vel_controller"] == "running"
                assert states["scaled_pos_joint_traj_controller"] == "stopped"
            else:
                assert states["position_joint_trajectory_controller"] == "running"

            moved = _jog(rospy, twist_pub, pose, cell["base"], distance=0.02, proc=driver.proc)
            assert np.all(np.abs(moved[1:]) < 0.25 * abs(moved[0])), f"tool tip left the X line: {moved}"
            _settle(rospy, cell["joints"])

            _gives_way_on_two_axes(rospy, pose, cc_status, cell["joints"])
            print(f"\n{robot} as {cell['profile']}: jogged 2 cm along -X; the follower gave way to 10 N "
                  "pushes along -X and +Y")

            if robot == "panda_custom":
                # Over franka's 20 N collision threshold: the reflex stops the arm until error recovery.
                mode = Collector("/mujoco_driver/robot_mode", String)
                mode.wait_for(1, timeout=5)
                assert mode.last().data == "move"
                push = PushEEFRequest(duration=0.3)
                push.wrench.force.z = -30.0
                assert rospy.ServiceProxy("/mujoco_driver/push", PushEEF)(push).success
                wait_until(lambda: mode.last().data == "reflex", 10, "the reflex to trip")
                _settle(rospy, cell["joints"])
                held = _jog(rospy, twist_pub, pose, cell["base"], messages=50, proc=driver.proc)
                assert np.linalg.norm(held) < 2e-3, f"the arm moved in reflex mode: {held}"
                recovery = actionlib.SimpleActionClient("/franka_control/error_recovery", ErrorRecoveryAction)
                assert recovery.wait_for_server(rospy.Duration(10))
                recovery.send_goal(ErrorRecoveryGoal())
                assert recovery.wait_for_result(rospy.Duration(10))
                wait_until(lambda: mode.last().data == "move", 5, "the robot mode back to move")
                moved = _jog(rospy, twist_pub, pose, cell["base"], distance=0.01, proc=driver.proc)
                print(f"{robot}: a 30 N push tripped the reflex; after error recovery the arm jogged again")
                mode.close()
        finally:
            pose.close()
            cc_status.close()
            twist_pub.unregister()


SRC = pathlib.Path(__file__).resolve().parents[2] / "src"
# Packages `make robot` wrote: their hardware.launch expects a generic ros_control driver (a
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


@pytest.mark.parametrize("robot", GENERATED)
def test_a_generated_hardware_launch_runs_unchanged_against_a_generic_driver(ros_node, robot):
    """What a user of a new arm gets from `make robot`: hardware.launch, with no argument, on a driver with
    the generic interface: a jog moves the tool tip along the line, a follower gives way to pushes on two
    axes."""
    import yaml

    rospy = ros_node
    base = yaml.safe_load((SRC / robot / "config/jog_arm_hardware.yaml").read_text())["planning_frame"]
    with run_launch("mujoco_driver", "emulated_robot.launch", args={"robot_package": robot}) as driver:
        driver.wait_for_topic("/joint_states", timeout=40)
        with run_launch(robot, "hardware.launch") as stack:
            stack.wait_for_service("/configure_cartesian_impedance", timeout=40)
            pose = Collector("/mujoco_driver/eef_pose", PoseStamped)
            cc_status = Collector("/contact_control_node/status", ContactControlStatus)
            twist_pub = rospy.Publisher("/jog_arm_server/delta_jog_cmds", TwistStamped, queue_size=1,
                                        tcp_nodelay=True)
            try:
                pose.wait_for(1, timeout=20)
                zeroed = lambda: cc_status.last() is not None and cc_status.last().safety == 0  # noqa: E731
                wait_until(zeroed, 20, "contact_control to zero the sensor")
                wait_until(lambda: twist_pub.get_num_connections() > 0, 10, "jog_arm's input subscribed")
                moved = _jog(rospy, twist_pub, pose, base, distance=0.02, proc=driver.proc)
                assert np.all(np.abs(moved[1:]) < 0.25 * abs(moved[0])), f"tool tip left the X line: {moved}"
                _settle(rospy, "/joint_states")
                _gives_way_on_two_axes(rospy, pose, cc_status, "/joint_states")
                print(f"\n{robot}: generated hardware.launch on the generic driver: jogged 2 cm along -X; "
                      "the follower gave way to 10 N pushes along -X and +Y")
            finally:
                pose.close()
                cc_status.close()
                twist_pub.unregister()
            stack.stop()
            assert stack.proc.returncode == 0, stack.output()[-3000:]
        driver.stop()
        assert driver.proc.returncode == 0, driver.output()[-3000:]
