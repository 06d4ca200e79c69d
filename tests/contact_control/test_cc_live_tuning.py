"""Live tuning: `dynparam set /contact_control_node max_velocity 0.05` while the hand-guided tool
moves at 0.2 m/s slows it to 0.05 m/s within the deceleration limit (no step); a bad value is refused with
the reason on ~status and changes nothing."""

from __future__ import annotations

import subprocess

import numpy as np
import pytest

pytest.importorskip("compliant_control_msgs.msg", reason="needs devel/setup.bash (make test sources it)")
pytest.importorskip("dynamic_reconfigure.server", reason="needs python3-dynamic-reconfigure (bootstrap)")


def _dynparam(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run(["rosrun", "dynamic_reconfigure", "dynparam", *args], capture_output=True,
                          text=True, timeout=30, check=False)


def test_a_lower_speed_clamp_slows_the_moving_tool_without_a_step_and_a_bad_value_is_refused(ros_node):
    rospy = ros_node
    from compliant_control_msgs.srv import Guide, PushEEF, PushEEFRequest
    from geometry_msgs.msg import TwistStamped
    from harness.launch import run_launch
    from harness.observed import SimArm
    from harness.waiting import Collector, wait_until

    with run_launch("ur5_custom", "sim.launch") as h:
        h.wait_for_service("/contact_control_node/set_parameters", timeout=40)
        got = _dynparam("get", "/contact_control_node")
        assert "'max_velocity': 0.25" in got.stdout, got.stdout + got.stderr
        with SimArm() as arm:
            guide = rospy.ServiceProxy("/contact_control_node/guide", Guide)
            assert guide(enable=True, axes=["x"]).success
            push = PushEEFRequest(duration=6.0)
            push.wrench.force.x = 10.0  # 10 N / 50 N/(m/s): 0.2 m/s
            assert rospy.ServiceProxy("/mujoco_driver/push", PushEEF)(push).success

            def speed() -> float:
                stamped = [(m.header.stamp.to_sec(), m.pose.position.x) for m in arm.pose.msgs[-30:]]
                (t0, x0), (t1, x1) = stamped[0], stamped[-1]
                return (x1 - x0) / (t1 - t0) if t1 > t0 else 0.0

            wait_until(lambda: speed() > 0.15, 10, "the guided tool at about 0.2 m/s")
            # The twists themselves, stamped with the time of the wrench each answers (the status timer's
            # stamps are its own: on a busy machine a late status made a step look steeper than it was).
            twists = Collector("/jog_arm_server/contact_cmds", TwistStamped)
            try:
                twists.wait_for(10, timeout=10)
                tuned = _dynparam("set", "/contact_control_node", "max_velocity", "0.05")
                assert tuned.returncode == 0, tuned.stderr
                wait_until(lambda: speed() < 0.055, 10, "the tool slowed to the new clamp")
            finally:
                twists.close()
            commanded = np.array([(m.header.stamp.to_sec(), m.twist.linear.x) for m in twists.msgs])
            slowing = -np.diff(commanded[:, 1]) / np.maximum(np.diff(commanded[:, 0]), 1e-3)
            print(f"\ncommanded {commanded[0, 1]:.3f} -> {commanded[-1, 1]:.3f} m/s, fastest slowing "
                  f"{slowing.max():.2f} m/s^2 (deceleration_linear 2.5)")
            assert commanded[:, 1].max() > 0.15 and commanded[-1, 1] <= 0.0501
            assert slowing.max() <= 2.5 * 1.02, slowing.max()  # bumpless: within the deceleration limit

            refused = _dynparam("set", "/contact_control_node", "max_velocity", "-1")
            assert refused.returncode == 0
            assert rospy.get_param("/contact_control_node/max_velocity") == pytest.approx(0.05)
            wait_until(lambda: "live tuning refused: parameter 'max_velocity': must be > 0" in (
                arm.status.last().message), 5, "the refusal's reason on ~status")
            assert "'max_velocity': 0.05" in _dynparam("get", "/contact_control_node").stdout
            assert speed() < 0.055  # still the accepted clamp
            assert guide(enable=False, axes=[]).success
        h.stop()
