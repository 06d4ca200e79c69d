"""End to end, ISO/TS 15066's hand (mujoco_driver fixture:=hand: 0.6 kg, 75 N/mm) lying on the block: a jog
down onto it from an outside source (the keyboard's path), held, pins the hand, below the hand's
quasi-static 140 N (the contact stop brakes hard); jog_arm releases the clamp below 10 N within a second of
the peak, says so, and the held key moves nothing more until it is let go of.

The robots: harness.hand_scene."""

from __future__ import annotations

import numpy as np
import pytest

pytest.importorskip("compliant_control_msgs.msg", reason="needs devel/setup.bash (make test sources it)")

from compliant_control_msgs.msg import JogStatus
from geometry_msgs.msg import TwistStamped, WrenchStamped
from harness.hand_scene import BASE_FRAME, LAYOUTS, hand_scene
from harness.waiting import Collector, wait_until

pytestmark = pytest.mark.cobot_safety

SPEED = 0.1  # [m/s] a keyboard's jog down onto the hand
HAND_LIMIT = 140.0  # [N] ISO/TS 15066 Annex A, hand, quasi-static


@pytest.mark.parametrize("robot, single_process", LAYOUTS)
def test_a_hand_pinned_by_a_jog_is_released_below_10_newtons_within_a_second(ros_node, robot, single_process):
    rospy = ros_node
    with hand_scene(robot, single_process, "hand") as h:
        h.wait_for_service("/contact_control_node/tare", timeout=40)
        wrench = Collector("/wrench", WrenchStamped, queue_size=20000)
        status = Collector("/jog_arm_server/status", JogStatus, queue_size=20000)
        pub = rospy.Publisher("/jog_arm_server/delta_jog_cmds", TwistStamped, queue_size=1, tcp_nodelay=True)
        try:
            for c in (wrench, status):
                c.wait_for(1, timeout=20)
            wait_until(lambda: pub.get_num_connections() > 0, 10, "jog_arm to subscribe to its input")
            f = wrench.last().wrench.force
            weight = np.array([f.x, f.y, f.z])  # the tool's weight at the start pose (tared away)
            twist = TwistStamped()
            twist.header.frame_id = BASE_FRAME[robot]
            twist.twist.linear.z = -SPEED
            rate = rospy.Rate(100)  # the sender's rate, like key_to_twist's repeat
            released_at = None
            start = rospy.get_time()
            while released_at is None or rospy.get_time() - released_at < 1.0:  # the key held 1 s more
                assert h.proc.poll() is None, h.output()[-3000:]
                said = status.last()
                assert rospy.get_time() - start < 30.0, f"no clamp release: {said.code_name} {said.message}"
                if released_at is None and "clamp released" in said.message:
                    released_at = rospy.get_time()
                twist.header.stamp = rospy.Time.now()
                pub.publish(twist)
                rate.sleep()  # the sender's rate, not a wait for a result
            ended = rospy.Time.now()
            wait_until(lambda: wrench.last().header.stamp >= ended, 10, "the wrench collector to catch up")
            sensed = [(m.header.stamp.to_sec(), m.wrench.force) for m in list(wrench.msgs)]
            t = np.array([s for s, _ in sensed])  # simulated time
            raw = np.linalg.norm(np.array([[v.x, v.y, v.z] for _, v in sensed]) - weight, axis=1)
            force = np.convolve(raw, np.ones(5) / 5, mode="same")  # 10 ms means: the force, not the noise
            peak = int(np.argmax(force))
            below = peak + int(np.argmax(force[peak:] < 10.0))
            saying = [m.message for m in status.msgs if m.code == JogStatus.CLAMP_RELEASE]
            print(f"\n{robot}: jog at {SPEED} m/s into the hand: peak {force[peak]:.0f} N, below 10 N "
                  f"{t[below] - t[peak]:.3f} s later, then at most "
                  f"{force[t >= t[below] + 0.05].max():.1f} N while the key was held; {saying[:1]}")
            assert force[peak] > 10.0, "the jog did not press the hand"
            assert force[peak] <= HAND_LIMIT  # the contact stop brakes before the hand's quasi-static one
            assert force[below] < 10.0 and t[below] - t[peak] < 1.0
            # The held key moved nothing more: from 50 ms after the crossing on (the release goes on to
            # clamp_release_force by the stack's compensated force; this raw reading minus the start's
            # weight sat up to 5 N above it).
            after = force[t >= t[below] + 0.05]
            assert after.size and after.max() < 10.0
            assert saying and "backing off along the force" in saying[0]
        finally:
            for c in (wrench, status):
                c.close()
            pub.unregister()
        h.stop()

