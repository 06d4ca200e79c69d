"""`roslaunch ur5_custom sim.launch viewer:=true` with a display (a private Xvfb, Mesa's software OpenGL):
MuJoCo's window opens, the arm still complies with a push while it is open, and the stack shuts down
cleanly with the window still open."""

from __future__ import annotations

import os

import numpy as np
import pytest

pytest.importorskip("cartesian_impedance_msgs.srv", reason="needs devel/setup.bash (make test sources it)")

from cartesian_impedance_msgs.msg import ControlLaw
from cartesian_impedance_msgs.srv import ConfigureForceControl, ConfigureForceControlRequest
from compliant_control_msgs.msg import ContactControlStatus
from compliant_control_msgs.srv import PushEEF, PushEEFRequest
from geometry_msgs.msg import PoseStamped
from harness.display import HAVE_XVFB, NO_XVFB, private_display, windows
from harness.launch import run_launch
from harness.waiting import Collector, wait_until

pytestmark = pytest.mark.skipif(not HAVE_XVFB, reason=NO_XVFB)


@pytest.fixture
def display():
    with private_display() as name:
        yield name


def test_viewer_opens_a_window_and_the_arm_still_complies(ros_node, display):
    rospy = ros_node
    env = {**os.environ, "DISPLAY": display}
    env.pop("WAYLAND_DISPLAY", None)
    with run_launch("ur5_custom", "sim.launch", args={"viewer": "true"}, env=env) as h:
        h.wait_for_topic("/mujoco_driver/eef_pose", timeout=40)
        h.wait_for_service("/configure_cartesian_impedance", timeout=40)
        try:
            wait_until(lambda: "MuJoCo" in windows(display), 20, "MuJoCo's window on the display")
        except AssertionError as err:  # once in 1310 tests (seed 777, busy cores): what the driver said
            raise AssertionError(f"{err}; windows: {windows(display)[-1500:]}; launch output: "
                                 f"{h.output()[-3000:]}") from None
        assert "running headless" not in h.output(), h.output()[-3000:]

        pose = Collector("/mujoco_driver/eef_pose", PoseStamped)
        try:
            pose.wait_for(1, timeout=20)
            # Set the law once the sensor is zeroed: a push now would be taken as the zero (see
            # contact_control's README, Zeroing).
            wait_until(lambda: rospy.wait_for_message(
                "/contact_control_node/status", ContactControlStatus, 5).safety == 0, 20, "the sensor zeroed")

            def tip() -> np.ndarray:
                p = pose.last().pose.position
                return np.array([p.x, p.y, p.z])

            req = ConfigureForceControlRequest()
            req.cart_impedance_params.damping.translational.x = 200.0
            req.direction_control_laws.x.type = ControlLaw.TYPE_FOLLOWER
            assert rospy.ServiceProxy("/configure_cartesian_impedance", ConfigureForceControl)(req).success
            before = tip()
            push = PushEEFRequest(duration=0.6)
            push.wrench.force.x = -10.0
            assert rospy.ServiceProxy("/mujoco_driver/push", PushEEF)(push).success
            wait_until(lambda: before[0] - tip()[0] > 0.01, 10, "the tool to follow the push along -X")
        finally:
            pose.close()
        assert "MuJoCo" in windows(display), "the window closed by itself"
        h.stop()
        assert h.proc.returncode == 0, h.output()[-3000:]
        assert "escalating" not in h.output(), "a node needed SIGTERM/SIGKILL to stop"
