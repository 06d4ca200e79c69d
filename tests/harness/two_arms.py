"""Two arms on one master (namespaces, cells): the names every ROS graph shares, a jog by a streamed twist,
a tool standing still."""

from __future__ import annotations

import os
import time
import xmlrpc.client

import numpy as np

from harness.waiting import Collector, wait_until

__all__ = ["SHARED", "Jogger", "master", "position", "standing_still"]

# What every ROS graph shares by convention: the log, tf (the prefixes keep the frames apart) and diagnostics.
SHARED = {"/rosout", "/rosout_agg", "/tf", "/tf_static", "/diagnostics", "/use_sim_time"}


def master() -> xmlrpc.client.ServerProxy:
    return xmlrpc.client.ServerProxy(os.environ["ROS_MASTER_URI"])


def position(poses: Collector) -> np.ndarray:
    """The newest pose's position [m] of a PoseStamped collector."""
    p = poses.last().pose.position
    return np.array([p.x, p.y, p.z])


def standing_still(poses: Collector) -> bool:
    """The last 0.2 s of the driver's 100 Hz tool poses within 0.1 mm."""
    recent = [m.pose.position for m in poses.wait_for(1)[-20:]]
    return len(recent) == 20 and np.ptp([[p.x, p.y, p.z] for p in recent], axis=0).max() < 1e-4


class Jogger:
    """Twists into an arm's jog_arm at 100 Hz, as keyboard_publisher's key repeat sends them."""

    def __init__(self, rospy, ns: str, frame: str, linear_z: float = 0.02) -> None:
        from geometry_msgs.msg import TwistStamped

        self._rospy = rospy
        self.pub = rospy.Publisher(f"/{ns}/jog_arm_server/delta_jog_cmds", TwistStamped, queue_size=1)
        wait_until(lambda: self.pub.get_num_connections() > 0, 10, f"{ns}'s jog_arm to subscribe")
        self.twist = TwistStamped()
        self.twist.header.frame_id = frame
        self.twist.twist.linear.z = linear_z

    def jog(self, seconds: float) -> None:
        began = self._rospy.get_time()
        while self._rospy.get_time() - began < seconds:
            self.twist.header.stamp = self._rospy.Time.now()
            self.pub.publish(self.twist)
            time.sleep(0.01)  # the sender's rate, as key_to_twist's repeat

    def close(self) -> None:
        self.pub.unregister()
