"""End to end, ISO/TS 15066's transient contact: a jog requested at 0.5 m/s down onto a hand held in the
air (mujoco_driver fixture:=free_hand: 0.6 kg, 75 N/mm, free to move when struck) reaches it at the speed
jog_arm's collaborative cap allows for the region, and the strike's force stays within the region's
transient limit.

For the hand the cap is above 0.5 m/s whatever the arm (280 N / sqrt(0.6 kg 75 N/mm) = 1.32 m/s for an
infinitely heavy one), so the jog goes at 0.5 m/s; for the face (65 N, 4.4 kg) it binds, and the same jog
goes at the cap. The robots: harness.hand_scene."""

from __future__ import annotations

import math

import numpy as np
import pytest

pytest.importorskip("compliant_control_msgs.msg", reason="needs devel/setup.bash (make test sources it)")

from compliant_control_msgs.msg import JogStatus
from geometry_msgs.msg import PoseStamped, TwistStamped, WrenchStamped
from harness.hand_scene import BASE_FRAME, LAYOUTS, hand_scene
from harness.waiting import Collector, wait_until
from jog_arm.body_regions import region_named

pytestmark = pytest.mark.cobot_safety

REQUESTED = 0.5  # [m/s] the jog down onto the hand
RISE = 0.25  # [m] the tool is first raised this far: room to reach the speed
TOUCH = 20.0  # [N] the contact begins (the contact guard's stop)


def _tips(poses: list) -> tuple[np.ndarray, np.ndarray]:
    stamps = np.array([m.header.stamp.to_sec() for m in poses])  # simulated time
    tips = np.array([[m.pose.position.x, m.pose.position.y, m.pose.position.z] for m in poses])
    return stamps, tips


def _jog(rospy, pub, frame: str, vz: float, until, limit: float) -> None:
    """Send a twist down (vz < 0) or up at 100 Hz, like a held key, until `until()` or `limit` [s]."""
    twist = TwistStamped()
    twist.header.frame_id = frame
    twist.twist.linear.z = vz
    rate, start = rospy.Rate(100), rospy.get_time()
    while not until() and rospy.get_time() - start < limit:
        twist.header.stamp = rospy.Time.now()
        pub.publish(twist)
        rate.sleep()  # the sender's rate, not a wait for a result


class Strike:
    """One strike: the tool raised RISE, then jogged down at REQUESTED until it touches the hand, the key
    held 0.3 s more; what the approach's speed, the cap and the force were."""

    def __init__(self, rospy, pub, frame: str, topics: dict) -> None:
        self.rospy, self.pub, self.frame = rospy, pub, frame
        self.wrench, self.status, self.poses = topics["wrench"], topics["status"], topics["poses"]
        self.weight = np.zeros(3)
        self.began = rospy.Time(0)
        self._seen, self._touched = 0, False  # wrenches checked for the touch, and whether one was over
        self.stale = 0  # jog_arm's STALE_COMMAND statuses during the approach
        self.last = (math.nan, math.nan, math.nan)  # the 0.1 s nearest the touch: (ratio, cap, speed)

    def _force(self, m) -> float:
        f = m.wrench.force
        return float(np.linalg.norm(np.array([f.x, f.y, f.z]) - self.weight))

    def touched(self) -> bool:
        """Any wrench since the jog down began over TOUCH (a 2 ms peak between two checks counts)."""
        msgs = self.wrench.msgs
        end = len(msgs)
        hit = any(m.header.stamp > self.began and self._force(m) > TOUCH for m in msgs[self._seen:end])
        self._seen = end
        self._touched = self._touched or hit
        return self._touched

    def run(self) -> tuple[float, float, float]:
        """(cap [m/s], approach speed [m/s] in the approach's fastest 0.1 s for its cap, peak force [N]);
        `last` keeps the 0.1 s just before the touch."""
        rospy, wrench, status, poses = self.rospy, self.wrench, self.status, self.poses
        start_z = poses.last().pose.position.z
        _jog(rospy, self.pub, self.frame, 0.1, lambda: poses.last().pose.position.z > start_z + RISE, 10.0)
        assert poses.last().pose.position.z > start_z + RISE, "the tool was not raised"
        wait_until(lambda: status.last().code in (JogStatus.NO_WARNING, JogStatus.STALE_COMMAND), 5,
                   "jog_arm to halt after the rise")
        settled = rospy.Time.now() + rospy.Duration(0.3)
        wait_until(lambda: wrench.last().header.stamp > settled, 10, "0.3 s of rest")
        f = wrench.last().wrench.force
        self.weight = np.array([f.x, f.y, f.z])  # tared away: the tool's weight here
        self.began = rospy.Time.now()
        self._seen = len(wrench.msgs)
        _jog(rospy, self.pub, self.frame, -REQUESTED, self.touched, 10.0)
        last, z = status.last(), poses.last().pose.position.z
        assert self.touched(), (f"the tool never reached the hand: {last.code_name} {last.message}, "
                                f"z {z:.4f} m, |F| {self._force(wrench.last()):.1f} N")
        _jog(rospy, self.pub, self.frame, -REQUESTED, lambda: False, 0.3)  # the key still held
        ended = rospy.Time.now()
        wait_until(lambda: poses.last().header.stamp >= ended, 10, "the pose collector to catch up")
        sensed = [m for m in list(wrench.msgs) if m.header.stamp > self.began]
        t = np.array([m.header.stamp.to_sec() for m in sensed])
        force = np.array([self._force(m) for m in sensed])  # raw 2 ms samples: the strike
        contact = t[int(np.argmax(force > TOUCH))]
        stamps, tips = _tips([m for m in list(poses.msgs) if m.header.stamp > self.began])
        statuses = [m for m in list(status.msgs) if m.header.stamp > self.began]
        self.stale = sum(m.code == JogStatus.STALE_COMMAND for m in statuses
                         if m.header.stamp.to_sec() < contact)
        # Each 0.1 s of the approach (stepped by 20 ms, up to 10 ms before the touch) against its cap: the
        # fastest, relative to what the cap allows, is the approach (a sender starved on a loaded machine
        # lets jog_arm halt for a moment, which slows some windows); the one nearest the touch is `last`.
        cap_t = np.array([m.header.stamp.to_sec() for m in statuses])
        cap_v = np.array([m.speed_cap for m in statuses])
        windows = []  # (speed / allowed, cap, speed), from the touch back
        for end in np.arange(contact - 0.01, float(self.began.to_sec()) + 0.1, -0.02):
            window = (stamps > end - 0.1) & (stamps < end)
            held = (cap_t > end - 0.1) & (cap_t < end)
            if window.sum() < 5 or not held.any():  # a loaded machine's driver drops some poses
                continue
            # A line fitted through the poses: one pose's stamp may be a step off (2 ms of 10).
            speed = float(np.linalg.norm(np.polyfit(stamps[window], tips[window], 1)[0]))
            cap = float(np.median(cap_v[held]))
            if cap <= 0.0:  # no cap reported (halted)
                continue
            windows.append((speed / min(REQUESTED, cap), cap, speed))
        assert windows, (f"no 0.1 s of the approach with poses and jog_arm's statuses: {len(stamps)} poses, "
                         f"{len(cap_t)} statuses in {contact - self.began.to_sec():.3f} s")
        self.last = windows[0]
        _, cap, speed = max(windows)
        return cap, speed, float(force.max())


@pytest.mark.parametrize("robot, single_process", LAYOUTS)
def test_a_strike_on_a_free_hand_is_capped_and_within_the_transient_limit(ros_node, robot, single_process):
    rospy = ros_node
    from dynamic_reconfigure.client import Client

    with hand_scene(robot, single_process, "free_hand") as h:
        topics = {"wrench": Collector("/wrench", WrenchStamped, queue_size=50000),
                  "status": Collector("/jog_arm_server/status", JogStatus, queue_size=50000),
                  "poses": Collector("/mujoco_driver/eef_pose", PoseStamped, queue_size=50000)}
        pub = rospy.Publisher("/jog_arm_server/delta_jog_cmds", TwistStamped, queue_size=1, tcp_nodelay=True)
        client = Client("/jog_arm_server", timeout=20)
        configured = rospy.get_param("/jog_arm_server/collaborative_region")
        report = []
        try:
            for c in topics.values():
                c.wait_for(1, timeout=20)
            wait_until(lambda: pub.get_num_connections() > 0, 10, "jog_arm to subscribe to its input")
            caps, speeds = {}, {}
            for name in ("hand", "face"):
                client.update_configuration({"collaborative_region": name})
                region = region_named(name)
                strike = Strike(rospy, pub, BASE_FRAME[robot], topics)
                cap, approach, peak = strike.run()
                caps[name] = cap
                report.append(f"{name}: cap {cap:.3f} m/s, approach {approach:.3f} m/s (just before the "
                              f"touch {strike.last[2]:.3f} m/s, cap {strike.last[1]:.3f}), peak {peak:.1f} N "
                              f"(limit {region.transient_force:.0f} N; {strike.stale} stale-command "
                              "statuses)")
                assert all(m.body_region == name for m in list(topics["status"].msgs)[-10:])
                # Never faster than allowed just before the touch (within 3 %: the fit's noise).
                assert strike.last[0] < 1.03, report[-1]
                if caps[name] < REQUESTED:  # a binding cap: the jog goes at it (its fastest 0.1 s, since a
                    # starved sender's pause slows some)
                    assert approach > 0.85 * cap, report[-1]
                speeds[name] = approach
                assert peak <= region.transient_force, report[-1]
            print(f"\n{robot}: " + "; ".join(report))
            assert caps["face"] < REQUESTED < caps["hand"], "a cap that binds and one that does not"
            # The hand's cap does not bind: far faster than the face's. (Whether it reaches the full 0.5 m/s
            # in the 0.25 m depends on the machine: jog_arm's acceleration is a step per cycle, and a loaded
            # machine runs fewer cycles per simulated second: the README, *Clamping*.)
            assert speeds["hand"] > 1.5 * caps["face"], "; ".join(report)
        finally:
            # The master outlives this launch: the next test's jog_arm must not find the face here.
            client.update_configuration({"collaborative_region": configured})
            for c in topics.values():
                c.close()
            pub.unregister()
            client.close()
        h.stop()
