"""End to end on the simulated UR5: the normal law turns the tool onto a sloping surface while Z presses.

The driver's `tilted` fixture turns the block 15 degrees about the base's Y axis; the tool (a 3 cm radius
cylinder, pointing down) touches it with one edge of its face. With Z force tracking 10 N and the normal
law on RX and RY, the tool's axis comes within 1.5 degrees of the slope's normal and the face lies flat.
Without the normal law (the control) it stays 15 degrees off.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

pytest.importorskip("compliant_control_msgs.srv", reason="needs devel/setup.bash (make test sources it)")

from compliant_control_msgs.msg import AxisLaw, ContactControlStatus
from compliant_control_msgs.srv import ConfigureLaws, ConfigureLawsRequest
from geometry_msgs.msg import PoseStamped
from harness.launch import run_launch
from harness.waiting import Collector, wait_until
from std_srvs.srv import Trigger

TILT = 0.2618  # [rad] mujoco_driver's surface_tilt default
NORMAL = np.array([math.sin(TILT), 0.0, math.cos(TILT)])  # the block's top, out of it
PRESS_TIME = 8.0  # [s] simulated: the turn at 0.1 rad/s, then the force settling while friction relaxes


def _axis(msg: PoseStamped) -> np.ndarray:
    """The tool's axis (the tool tip frame's z) in the base frame."""
    q = msg.pose.orientation
    x, y, z, w = q.x, q.y, q.z, q.w
    return np.array([2 * (x * z + y * w), 2 * (y * z - x * w), 1 - 2 * (x * x + y * y)])


def _off_normal(msg: PoseStamped) -> float:
    """The angle [deg] between the tool's axis and the inward normal of the slope."""
    return math.degrees(math.acos(float(np.clip(_axis(msg) @ -NORMAL, -1.0, 1.0))))


def _press(normal: bool) -> ConfigureLawsRequest:
    req = ConfigureLawsRequest()
    req.z.law, req.z.damping, req.z.velocity = AxisLaw.FORCE_TRACKING, 2000.0, 0.005
    req.z.target_force, req.z.force_limit, req.z.exceeded_action = 10.0, 20.0, AxisLaw.ACTION_MOVE_AWAY
    if normal:
        for axis in (req.rx, req.ry):
            axis.law, axis.stiffness, axis.velocity, axis.max_travel = AxisLaw.NORMAL, 2.0, 0.1, 0.5
    return req


def _touch() -> ConfigureLawsRequest:
    """Down at 20 mm/s until 1 N: faster than force tracking's approach, which takes over from there."""
    req = ConfigureLawsRequest()
    req.z.law, req.z.velocity, req.z.force_limit, req.z.max_travel = AxisLaw.COMPLIANT_MOVE, -0.02, 1.0, 0.1
    return req


@pytest.fixture(scope="module")
def stack(ros_node):
    rospy = ros_node
    with run_launch("ur5_custom", "sim.launch", {"fixture": "tilted"}) as h:
        h.wait_for_topic("/mujoco_driver/eef_pose", timeout=60)
        h.wait_for_service("/configure_laws", timeout=60)
        pose = Collector("/mujoco_driver/eef_pose", PoseStamped)
        status = Collector("/contact_control_node/status", ContactControlStatus)
        try:
            pose.wait_for(1, timeout=20)
            status.wait_for(1, timeout=20)
            yield type("Stack", (), {
                "pose": pose, "status": status,
                "configure": rospy.ServiceProxy("/configure_laws", ConfigureLaws),
                "stop": rospy.ServiceProxy("/contact_control_node/stop", Trigger),
                "reset": rospy.ServiceProxy("/mujoco_driver/reset", Trigger),
                "tare": rospy.ServiceProxy("/contact_control_node/tare", Trigger),
            })
        finally:
            pose.close()
            status.close()


def _pressed(stack, normal: bool, seconds: float = PRESS_TIME) -> tuple[float, list[float]]:
    """From the start pose: touch, then press 10 N for `seconds` (the normal law on or off); the
    tool's angle to the slope's normal [deg] at the start and the base-frame forces of the last second."""
    stack.stop()
    assert stack.reset().success
    wait_until(lambda: not stack.status.last().move_active, 5, "the stop")
    wait_until(lambda: stack.tare().success, 10, "a tare (wrenches again after the reset)")
    start = _off_normal(stack.pose.last())
    stack.status.clear()
    assert stack.configure(_touch()).success
    wait_until(lambda: stack.status.msgs and not stack.status.last().move_active
               and stack.status.last().wrench.force.z > 0.5, 15, "the touch")
    answer = stack.configure(_press(normal))
    assert answer.success, answer.message
    t0 = stack.pose.last().header.stamp.to_sec()
    stack.status.clear()
    wait_until(lambda: stack.pose.last().header.stamp.to_sec() - t0 > seconds, 40, "the press")
    last = stack.status.last()
    assert last.move_active, last.message
    forces = [m.wrench.force.z for m in stack.status.msgs if m.header.stamp.to_sec() > t0 + seconds - 1.0]
    return start, forces


def test_the_tool_turns_onto_the_slope_and_presses_10_n_along_it(stack):
    start, forces = _pressed(stack, normal=True)
    assert start == pytest.approx(15.0, abs=0.5)
    off = _off_normal(stack.pose.last())
    print(f"\nnormal law on the 15-degree slope: {off:.2f} deg off the normal; force z "
          f"{np.mean(forces):.2f} N (min {min(forces):.2f}, max {max(forces):.2f})")
    assert off < 1.5
    assert np.mean(forces) == pytest.approx(10.0, abs=1.0)
    # without the normal law the tool stays where it was: the slope's 15 degrees off
    _pressed(stack, normal=False, seconds=3.0)
    assert _off_normal(stack.pose.last()) == pytest.approx(15.0, abs=1.0)
    stack.stop()
