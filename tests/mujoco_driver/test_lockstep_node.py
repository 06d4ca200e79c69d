"""The driver's lockstep end to end: a silent stack pauses the simulated time of a driven arm, the echo topic
holds it for a controller apart, a give-up lets the watchdog stop the arm (simulated time read on /clock)."""

from __future__ import annotations

import os
import pathlib
import signal
import subprocess
import sys
import time

import numpy as np
import pytest

pytest.importorskip("compliant_control_msgs.srv", reason="needs devel/setup.bash (make test sources it)")

from geometry_msgs.msg import WrenchStamped
from harness.launch import run_node
from harness.waiting import Collector, wait_until
from rosgraph_msgs.msg import Clock
from sensor_msgs.msg import JointState
from std_msgs.msg import Float64MultiArray
from std_srvs.srv import Trigger

ROOT = pathlib.Path(__file__).resolve().parents[2]
CONFIG = ROOT / "src" / "ur5_custom" / "config"
NS = "/ls_test"
LEAD = 0.05  # [s] simulated: the test's own commands come at ~100 Hz of a loaded machine's wall clock
WAIT = 1.0  # [s] wall


@pytest.fixture(scope="module")
def driver(ros_node):
    script = ROOT / "src/control_stack/scripts/make_description"
    urdf = subprocess.run([sys.executable, str(script), f"@{CONFIG / 'description.args'}"],
                          capture_output=True, text=True, check=True, timeout=60).stdout
    ros_node.set_param(f"{NS}/robot_description", urdf)
    params = {"scene_config": str(CONFIG / "sim.yaml"), "publish_clock": True, "lockstep_lead": LEAD,
              "lockstep_wait": WAIT, "command_timeout": 0.1, "lockstep_echo_topic": f"{NS}/echo"}
    with run_node("mujoco_driver", "mujoco_driver", args=[f"__ns:={NS}"], params=params,
                  name="mujoco_driver") as h:
        # Its own service and topic: /clock may have other publishers on the session's master.
        h.wait_for_service(f"{NS}/mujoco_driver/reset")
        h.wait_for_topic(f"{NS}/joint_states")
        yield h


class Arm:
    def __init__(self, rospy, handle) -> None:
        self.rospy, self.handle = rospy, handle
        self.clock = Collector("/clock", Clock)
        self.joints = Collector(f"{NS}/joint_states", JointState)
        self.echo_pub = rospy.Publisher(f"{NS}/echo", WrenchStamped, queue_size=1, tcp_nodelay=True)
        self.echoing = False
        self.wrench = rospy.Subscriber(f"{NS}/wrench", WrenchStamped, self._echo, queue_size=1,
                                       tcp_nodelay=True)
        self.velocity_pub = rospy.Publisher(f"{NS}/joint_group_velocity_controller/command",
                                            Float64MultiArray, queue_size=1, tcp_nodelay=True)
        for pub in (self.velocity_pub, self.echo_pub):
            try:
                wait_until(lambda pub=pub: pub.get_num_connections() > 0, 10, f"the driver on {pub.name}")
            except AssertionError as err:  # say whether the driver still runs, and what it printed
                alive = "running" if handle.proc.poll() is None else f"exited with {handle.proc.returncode}"
                raise AssertionError(f"{err} (the driver: {alive})\n{handle.output()[-3000:]}") from None
        self.clock.wait_for(1)
        self.joints.wait_for(1)

    def _echo(self, msg: WrenchStamped) -> None:
        if self.echoing:
            self.echo_pub.publish(msg)  # a controller apart answering the state it read

    def now(self) -> float:
        return self.clock.last().clock.to_sec()

    def wrist(self) -> float:
        return self.joints.last().position[-1]

    def command(self, speed: float, wall_seconds: float) -> None:
        """Commands wrist_3 at `speed` [rad/s] at ~100 Hz for `wall_seconds`, as a controller would."""
        msg = Float64MultiArray(data=[0.0] * 5 + [speed])
        end = time.monotonic() + wall_seconds
        while time.monotonic() < end:
            self.velocity_pub.publish(msg)
            time.sleep(0.01)  # the sender's rate

    def close(self) -> None:
        self.wrench.unregister()
        self.clock.close()
        self.joints.close()


@pytest.fixture
def arm(driver, ros_node):
    """The driver after ~reset (which forgets an echo an earlier test left armed), and its topics."""
    driver.wait_for_service(f"{NS}/mujoco_driver/reset", 10)  # says whether it died, with its output
    assert ros_node.ServiceProxy(f"{NS}/mujoco_driver/reset", Trigger)().success
    a = Arm(ros_node, driver)
    yield a
    a.command(0.0, 0.05)
    a.close()


def _stalled(arm: Arm, seconds: float) -> tuple[float, float]:
    """Simulated time and wrist angle advanced during `seconds` of wall time in which nothing commands."""
    t0, q0 = arm.now(), arm.wrist()
    time.sleep(seconds)  # the stall being emulated: wall time during which the stack says nothing
    return arm.now() - t0, arm.wrist() - q0


def test_a_silent_stack_pauses_a_driven_arm_then_the_watchdog_stops_it(arm):
    start = arm.wrist()
    arm.command(0.5, 0.3)
    assert arm.wrist() - start > 0.02, "the commands did not turn the wrist"
    ran, turned = _stalled(arm, 0.5 * WAIT)
    # Without lockstep the simulation runs on: 0.5 s, and the arm turns until command_timeout (0.05 rad).
    assert ran <= LEAD + 0.01 and turned <= 0.5 * (LEAD + 0.01), (ran, turned)
    wait_until(lambda: "lockstep: no velocity command" in arm.handle.output(), 10, "the give-up")
    t0 = arm.now()
    wait_until(lambda: arm.now() > t0 + 0.5, 10, "the simulation to run on after the give-up")
    assert abs(arm.joints.last().velocity[-1]) < 1e-3, "command_timeout did not stop the arm"


def test_a_freeze_of_the_whole_machine_is_not_a_silent_stack(arm):
    arm.command(0.5, 0.3)
    _stalled(arm, 0.2)  # the driver holds the simulation, waiting for the stack
    gave_up = arm.handle.output().count("lockstep: no")
    os.killpg(arm.handle.proc.pid, signal.SIGSTOP)  # the driver frozen with the stack (this test: silent)
    try:
        time.sleep(1.5 * WAIT)
    finally:
        os.killpg(arm.handle.proc.pid, signal.SIGCONT)
    time.sleep(0.1)  # the stack wakes a little later: the driver waits for it, awake, for 0.1 s of WAIT
    t0 = arm.now()
    arm.command(0.5, 0.1)
    wait_until(lambda: arm.now() > t0, 10, "the simulation to go on with the commands")
    assert arm.handle.output().count("lockstep: no") == gave_up, arm.handle.output()[-2000:]


def test_a_zero_command_or_a_trajectory_lets_the_simulation_run(arm):
    """After a zero command the simulation runs on with nothing commanding, as far as it likes (a held one
    stops LEAD on), and the driver never gives up on a stack it is not waiting for."""
    arm.command(0.0, 0.1)
    gave_up = arm.handle.output().count("lockstep: no")
    t0 = arm.now()
    wait_until(lambda: arm.now() > t0 + 0.3, 10, "the simulation to run 0.3 s on without commands")
    assert arm.handle.output().count("lockstep: no") == gave_up, arm.handle.output()[-2000:]


def test_a_silent_controller_apart_holds_the_simulation_while_jog_arm_goes_on_commanding(arm):
    arm.echoing = True
    arm.command(0.5, 0.3)
    t0, q0 = arm.now(), arm.wrist()
    arm.echoing = False  # contact_control stalls; jog_arm goes on with its held twist
    arm.command(0.5, 0.5 * WAIT)
    ran, turned = arm.now() - t0, arm.wrist() - q0
    assert ran <= LEAD + 0.02 and turned <= 0.5 * (LEAD + 0.02), (ran, turned)
    # After the give-up the commands alone pace it; an echo again holds it again.
    wait_until(lambda: "lockstep: no echo" in arm.handle.output(), 10, "the give-up on the echo")
    t1 = arm.now()
    arm.command(0.5, 0.5)
    assert arm.now() - t1 > 0.2
    arm.echoing = True
    arm.command(0.5, 0.2)
    arm.echoing = False
    t2 = arm.now()
    arm.command(0.5, 0.5 * WAIT)
    assert arm.now() - t2 <= LEAD + 0.02
    assert np.isfinite(arm.wrist())
