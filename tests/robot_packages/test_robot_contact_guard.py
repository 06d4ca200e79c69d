"""End to end: jogging into the obstacle block from an outside source (a TwistStamped stream into
/jog_arm_server/delta_jog_cmds, the keyboard's path) is slowed and stopped by jog_arm's contact-force guard,
and the press it held back is released below 3 N as a clamp (the collaborative setting); ~status says why;
a twist away from the contact moves the arm out.

The UR5 runs the default single process (control_stack: the guard reads contact_control's force in-process),
the Panda the two-node layout (jog_arm reads contact_control's ~contact_wrench topic)."""

from __future__ import annotations

import time

import numpy as np
import pytest

pytest.importorskip("compliant_control_msgs.msg", reason="needs devel/setup.bash (make test sources it)")

from compliant_control_msgs.msg import JogStatus
from geometry_msgs.msg import PoseStamped, TwistStamped, WrenchStamped
from harness.launch import run_launch
from harness.process import node_pid, stalled
from harness.waiting import Collector, wait_until

BASE_FRAME = {"ur5_custom": "base_link", "panda_custom": "panda_link0"}
JOG_SPEED = 0.01  # [m/s] down onto the block, 7 cm below the start pose
GUARD_FORCE = 20.0  # [N] contact_guard_max_force in jog_arm's YAML
# Faster, the force overshoots the guard by about speed x 50 ms (jog_arm and the servos) x 20 N/mm (the stiff
# arm on the block) before the guard's stop takes effect (peaks of 52-127 N measured).


FAST = 0.05  # [m/s] a keyboard-like speed: the guard cannot stop the touch in time, but stops the press


@pytest.mark.parametrize(
    "robot, single_process, speed",
    [("ur5_custom", True, JOG_SPEED), ("panda_custom", False, JOG_SPEED), ("ur5_custom", True, FAST)],
)
def test_jogging_into_the_block_stops_under_the_guard_force_and_backing_out_works(ros_node, robot,
                                                                                   single_process, speed):
    rospy = ros_node
    with run_launch(robot, "sim.launch", args={"single_process": str(single_process).lower()}) as h:
        _wait_for_stack(h)
        pose = Collector("/mujoco_driver/eef_pose", PoseStamped)
        wrench = Collector("/wrench", WrenchStamped)
        status = Collector("/jog_arm_server/status", JogStatus)
        pub = rospy.Publisher("/jog_arm_server/delta_jog_cmds", TwistStamped, queue_size=1, tcp_nodelay=True)
        try:
            for c in (pose, wrench, status):
                c.wait_for(1, timeout=20)
            wait_until(lambda: pub.get_num_connections() > 0, 10, "jog_arm to subscribe to its input")

            def force() -> np.ndarray:
                f = wrench.last().wrench.force
                return np.array([f.x, f.y, f.z])

            def z() -> float:
                return pose.last().pose.position.z

            weight = force()  # the tool's weight at the start pose, in the sensor frame (tared away)
            twist = TwistStamped()
            twist.header.frame_id = BASE_FRAME[robot]
            rate = rospy.Rate(100)  # the sender's rate, like key_to_twist's repeat

            def jog(vz: float, until, seconds_after: float, what: str, deadline: float = 20.0) -> None:
                """Streams a twist of vz along Z until `until()`, then `seconds_after` more (simulated s)."""
                twist.twist.linear.z = vz
                start = rospy.get_time()
                done_at = None
                while done_at is None or rospy.get_time() - done_at < seconds_after:
                    assert h.proc.poll() is None, h.output()[-3000:]
                    assert rospy.get_time() - start < deadline, f"timed out: {what}"
                    if done_at is None and until():
                        done_at = rospy.get_time()
                    twist.header.stamp = rospy.Time.now()
                    pub.publish(twist)
                    rate.sleep()  # the sender's rate, not a wait for a result

            z0 = z()
            wrench.clear()
            # Down onto the block until the guard speaks (a hard touch may go straight to the clamp).
            acting = (JogStatus.CONTACT_GUARD, JogStatus.CLAMP_RELEASE)
            jog(-speed, lambda: status.last().code in acting or "clamp released" in status.last().message,
                0.0, "the guard to act")
            # Keep the key down while the clamp backs off; then 1 s more of pushing.
            jog(-speed, lambda: "backing off" not in status.last().message, 1.0, "the backing off to end")
            stopped = rospy.Time.now()
            # The collectors may trail the stack on 2 cores: read once they caught up with the key's release.
            wait_until(lambda: min(wrench.last().header.stamp, status.last().header.stamp) >= stopped, 10,
                       "the collectors to catch up")
            sensed = [(m.header.stamp.to_sec(), m.wrench.force) for m in list(wrench.msgs)]
            t = np.array([s for s, _ in sensed])
            contact = np.linalg.norm(np.array([[f.x, f.y, f.z] for _, f in sensed]) - weight, axis=1)
            peak = float(np.max(contact))
            held = float(np.mean(contact[(t > stopped.to_sec() - 0.5) & (t <= stopped.to_sec())]))
            said = next(m for m in reversed(list(status.msgs)) if m.header.stamp <= stopped)
            print(f"\n{robot}: guard force when jogging into the block at {speed} m/s: peak {peak:.2f} N, "
                  f"held {held:.2f} N (guard {GUARD_FORCE:g} N); went down {(z0 - z()) * 1e3:.1f} mm; "
                  f"status {said.code_name}: {said.message}")
            assert z0 - z() > 0.05, "it did not reach the block"
            # The guard slows the push from 2 N on; with the collaborative setting on (every robot package's
            # default) a press it holds back over clamp_push_force (10 N) for clamp_hold is a clamp, backed
            # off below 3 N, and the held key presses no more until its stream pauses (jog_arm README,
            # Clamping). After a hard touch the guard's own retreat may already have taken the force under
            # 10 N. This raw reading sits up to a few N above the stack's compensated one; a pause in this
            # sender's stream on a loaded machine would press again before the next release. Without the
            # clamp rule the press held 19.6-21.6 N.
            assert held <= 12.0, held
            guarded = said.code == JogStatus.CONTACT_GUARD and "moving away is allowed" in said.message
            if speed <= JOG_SPEED:
                # Slow enough for the guard's slow zone, which would land it at 20 N: released instead.
                assert "clamp released" in said.message, said.message
                assert peak <= GUARD_FORCE + (0.5 if single_process else 2.0), peak
            else:
                assert guarded or "clamp released" in said.message, said.message
            # Away from the contact: up 2 cm.
            pressed = z()
            jog(JOG_SPEED, lambda: z() - pressed > 0.02, 0.0, "the arm to back out")
            wait_until(lambda: np.linalg.norm(force() - weight) < 2.0, 5, "the contact to be released")
        finally:
            for c in (pose, wrench, status):
                c.close()
            pub.unregister()
        h.stop()


@pytest.mark.parametrize("robot, single_process, stalled_node", [
    ("panda_custom", False, "/contact_control_node"), ("ur5_custom", True, "/control_stack")])
def test_a_stalled_controller_pauses_the_simulation_instead_of_letting_the_jog_press_on(ros_node, robot,
                                                                                        single_process,
                                                                                        stalled_node):
    """The controller stops for 0.5 s (SIGSTOP, as a busy machine deschedules it) while jogging into the
    block: two nodes, contact_control stops and jog_arm goes on jogging on the last force it heard; one
    process, the commands stop and the driver holds the last one. The driver's lockstep holds the simulated
    arm until the stack answers again (README of mujoco_driver, Lockstep), so the guard still stops the press
    at its force; without it the press goes on at the slow-zone speed (44 N and 72 N measured)."""
    rospy = ros_node
    with run_launch(robot, "sim.launch", args={"single_process": str(single_process).lower()}) as h:
        _wait_for_stack(h)
        wrench = Collector("/wrench", WrenchStamped)
        status = Collector("/jog_arm_server/status", JogStatus)
        pub = rospy.Publisher("/jog_arm_server/delta_jog_cmds", TwistStamped, queue_size=1, tcp_nodelay=True)
        try:
            wrench.wait_for(1, timeout=20)
            status.wait_for(1, timeout=20)
            wait_until(lambda: pub.get_num_connections() > 0, 10, "jog_arm to subscribe to its input")
            weight = _force(wrench.last())
            twist = TwistStamped()
            twist.header.frame_id = BASE_FRAME[robot]
            twist.twist.linear.z = -JOG_SPEED
            rate = rospy.Rate(100)  # the sender's rate, like key_to_twist's repeat

            def jog_while(condition, what: str, deadline: float = 20.0) -> None:
                start = rospy.get_time()
                while condition():
                    assert h.proc.poll() is None, h.output()[-3000:]
                    assert rospy.get_time() - start < deadline, f"timed out: {what}"
                    twist.header.stamp = rospy.Time.now()
                    pub.publish(twist)
                    rate.sleep()  # the sender's rate, not a wait for a result

            def contact() -> float:
                return float(np.linalg.norm(_force(wrench.last()) - weight))

            jog_while(lambda: contact() < 8.0, "the touch")
            with stalled(node_pid(stalled_node)) as t0:
                jog_while(lambda: time.monotonic() - t0 < 0.5, "the stall", deadline=5.0)
            jog_while(lambda: status.last().code != JogStatus.CONTACT_GUARD, "the guard to act")
            stopped = rospy.Time.now()
            jog_while(lambda: rospy.get_time() - stopped.to_sec() < 0.5, "the key held after the guard")
            wait_until(lambda: wrench.last().header.stamp >= rospy.Time.now() - rospy.Duration(0.1), 10,
                       "the wrenches to catch up")
            peak = max(float(np.linalg.norm(_force(m) - weight)) for m in list(wrench.msgs))
            print(f"\n{robot}: {stalled_node} stalled 0.5 s while jogging into the block: peak {peak:.2f} N")
            assert peak <= GUARD_FORCE + 2.0, peak
            assert "lockstep: no" not in h.output()  # paused, never given up on in 0.5 s
        finally:
            wrench.close()
            status.close()
            pub.unregister()
        h.stop()


def _force(msg: WrenchStamped) -> np.ndarray:
    f = msg.wrench.force
    return np.array([f.x, f.y, f.z])


def _wait_for_stack(h) -> None:
    for topic in ("/mujoco_driver/eef_pose", "/wrench", "/jog_arm_server/status"):
        h.wait_for_topic(topic, timeout=40)
    h.wait_for_service("/contact_control_node/tare", timeout=40)
