"""End to end, both robots: the rotational laws with a simulated human turning the tool.

A torque push about the base Z axis (mujoco_driver `~push` with `wrench.torque.z`) under an RZ follower turns
the tool the way it is pushed, at about tau / b, and the other way for the opposite push; under an RZ spring
the tool gives way to the push and turns back toward its start after the release."""

from __future__ import annotations

import numpy as np
import pytest

pytest.importorskip("compliant_control_msgs.srv", reason="needs devel/setup.bash (make test sources it)")

from compliant_control_msgs.msg import ContactControlStatus
from compliant_control_msgs.srv import ConfigureLaws, ConfigureLawsRequest, PushEEF, PushEEFRequest
from geometry_msgs.msg import PoseStamped
from harness.launch import run_launch
from harness.waiting import Collector, wait_until
from std_srvs.srv import Trigger

TORQUE = 4.0  # [Nm] about base Z: over the follower's 2.5 Nm deadband
DAMPING = 20.0  # [Nm/(rad/s)]: 0.2 rad/s for the push, under the 0.25 rad/s clamp
STIFFNESS = 5.0  # [1/s] of the spring: equilibrium 4 / (20 * 5) = 0.04 rad under the push


def _rotation(msg: PoseStamped) -> np.ndarray:
    q = msg.pose.orientation
    x, y, z, w = q.x, q.y, q.z, q.w
    return np.array([
        [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
        [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
        [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
    ])


def _yaw(R0: np.ndarray, msg: PoseStamped) -> float:
    """Rotation of the tool about the base Z axis since R0 [rad] (right-handed: +Z torque turns it +)."""
    R = _rotation(msg) @ R0.T
    return float(np.arctan2(R[1, 0] - R[0, 1], R[0, 0] + R[1, 1]))


@pytest.fixture(scope="module", params=["ur5_custom", "panda_custom"])
def stack(request, ros_node):
    rospy = ros_node
    with run_launch(request.param, "sim.launch") as h:
        h.wait_for_topic("/mujoco_driver/eef_pose", timeout=60)
        h.wait_for_service("/configure_laws", timeout=60)
        h.wait_for_service("/mujoco_driver/push", timeout=60)
        pose = Collector("/mujoco_driver/eef_pose", PoseStamped)
        status = Collector("/contact_control_node/status", ContactControlStatus)
        try:
            pose.wait_for(1, timeout=20)
            status.wait_for(1, timeout=20)
            yield type("Stack", (), {
                "robot": request.param.split("_")[0], "h": h, "pose": pose, "status": status,
                "configure": rospy.ServiceProxy("/configure_laws", ConfigureLaws),
                "push": rospy.ServiceProxy("/mujoco_driver/push", PushEEF),
                "stop": rospy.ServiceProxy("/contact_control_node/stop", Trigger),
                "reset": rospy.ServiceProxy("/mujoco_driver/reset", Trigger),
                "tare": rospy.ServiceProxy("/contact_control_node/tare", Trigger),
            })
        finally:
            pose.close()
            status.close()


def _still(stack, window: int = 150, tolerance: float = 2e-4) -> bool:
    """The last `window` poses (0.3 s at 500 Hz) moved less than `tolerance` (rad and m)."""
    msgs = list(stack.pose.msgs)[-window:]
    if len(msgs) < window:
        return False
    yaws = [_yaw(_rotation(msgs[0]), m) for m in msgs]
    tips = np.array([[m.pose.position.x, m.pose.position.y, m.pose.position.z] for m in msgs])
    return float(np.ptp(yaws)) < tolerance and float(np.ptp(tips, axis=0).max()) < tolerance


def _start(stack, law: ConfigureLawsRequest) -> tuple[np.ndarray, np.ndarray]:
    """Resets the scene, tares, sets the laws; returns the start orientation and tool tip position."""
    stack.stop()
    assert stack.reset().success
    stack.pose.clear()
    wait_until(lambda: _still(stack), 10, "the arm to settle after the reset")
    assert stack.tare().success
    answer = stack.configure(law)
    assert answer.success, answer.message
    wait_until(lambda: stack.status.last().move_active, 5, "the laws to be active")
    last = stack.pose.last()
    p = last.pose.position
    return _rotation(last), np.array([p.x, p.y, p.z])


def _push(stack, torque_z: float, seconds: float) -> None:
    req = PushEEFRequest(duration=seconds)
    req.wrench.torque.z = torque_z
    assert stack.push(req).success


def _push_and_record(stack, R0, torque_z: float, seconds: float) -> list[tuple[float, float]]:
    """Pushes and records (time, yaw) until the tool has been still for 0.3 s after the push."""
    stack.pose.clear()
    _push(stack, torque_z, seconds)
    t0 = stack.pose.wait_for(1)[0].header.stamp.to_sec()
    wait_until(lambda: stack.pose.last().header.stamp.to_sec() - t0 > seconds and _still(stack), 20,
               "the push to end and the tool to come to rest")
    return [(m.header.stamp.to_sec() - t0, _yaw(R0, m)) for m in list(stack.pose.msgs)]


def test_rz_follower_turns_the_tool_the_way_it_is_pushed(stack):
    law = ConfigureLawsRequest()
    law.rz.law, law.rz.damping = 1, DAMPING
    R0, tip0 = _start(stack, law)
    pushed = _push_and_record(stack, R0, TORQUE, 1.0)
    t = np.array([s for s, _ in pushed])
    yaw = np.array([y for _, y in pushed])
    steady = (t > 0.5) & (t < 1.0)
    rate = float(np.polyfit(t[steady], yaw[steady], 1)[0])
    turned = yaw[-1]
    p = stack.pose.last().pose.position
    drift = float(np.linalg.norm(np.array([p.x, p.y, p.z]) - tip0))
    # And back: the opposite torque turns it the other way.
    back = _push_and_record(stack, R0, -TORQUE, 1.0)
    returned = back[-1][1]
    stack.stop()
    print(f"\n{stack.robot}: RZ follower (b = {DAMPING:g}): +{TORQUE:g} Nm for 1 s turned the tool "
          f"{np.degrees(turned):.1f} deg at {rate:.3f} rad/s (tau/b = {TORQUE / DAMPING:.3f}); the tip moved "
          f"{drift * 1e3:.2f} mm; -{TORQUE:g} Nm turned it back to {np.degrees(returned):.1f} deg")
    assert turned > 0.1, "a +Z torque must turn the tool +Z (counter-clockwise seen from above)"
    assert abs(rate - TORQUE / DAMPING) <= 0.2 * TORQUE / DAMPING, rate
    assert drift < 2e-3, "a pure torque must not move the tool tip"
    assert returned < turned - 0.1, "the opposite torque must turn it back"


def test_rz_spring_gives_way_and_returns_toward_its_start(stack):
    law = ConfigureLawsRequest()
    law.rz.law, law.rz.damping, law.rz.stiffness = 2, DAMPING, STIFFNESS
    R0, _ = _start(stack, law)
    record = _push_and_record(stack, R0, TORQUE, 2.0)
    t = np.array([s for s, _ in record])
    yaw = np.array([y for _, y in record])
    excursion = float(np.max(yaw[t <= 2.0]))
    final = float(yaw[-1])
    overshoot = max(0.0, -float(np.min(yaw[t > 2.0])))
    stack.stop()
    equilibrium = TORQUE / (DAMPING * STIFFNESS)
    print(f"\n{stack.robot}: RZ spring (b = {DAMPING:g}, k = {STIFFNESS:g}): +{TORQUE:g} Nm for 2 s turned "
          f"it {np.degrees(excursion):.2f} deg (equilibrium {np.degrees(equilibrium):.2f}); "
          f"released it came back to {np.degrees(final):.2f} deg, overshoot {np.degrees(overshoot):.2f} deg")
    assert excursion > 0.02, "the spring did not give way to the torque"
    assert abs(final) < 0.3 * excursion, "released, the spring did not turn back toward its start"
    assert overshoot < 0.1 * excursion
