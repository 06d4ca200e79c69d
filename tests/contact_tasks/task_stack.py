"""The simulated UR5 with task_server, for the end-to-end task tests."""

from __future__ import annotations

import contextlib
import math
from collections.abc import Callable, Iterator

import actionlib
import numpy as np
import rospy
import tf2_ros
from compliant_control_msgs.msg import ExecuteTaskAction
from harness.launch import Launched, run_launch
from harness.waiting import wait_until


@contextlib.contextmanager
def task_stack(args: dict | None = None) -> Iterator[tuple[Launched, actionlib.SimpleActionClient,
                                                           Callable[[], np.ndarray]]]:
    """ur5_custom's sim.launch with `args`: the launch, task_server's ExecuteTask client and the tool tip's
    position and yaw in base_link (tf): x, y, z [m], yaw [rad]."""
    with run_launch("ur5_custom", "sim.launch", args or {}) as h:
        h.wait_for_service("/named_poses/move_to", timeout=40)
        client = actionlib.SimpleActionClient("/task_server/execute", ExecuteTaskAction)
        assert client.wait_for_server(rospy.Duration(30.0))
        buffer = tf2_ros.Buffer()
        listener = tf2_ros.TransformListener(buffer)  # noqa: F841 (fills the buffer)
        wait_until(lambda: buffer.can_transform("base_link", "tool_tip", rospy.Time(0)), 20, "the tool's tf")

        def tool() -> np.ndarray:
            t = buffer.lookup_transform("base_link", "tool_tip", rospy.Time(0)).transform
            p, q = t.translation, t.rotation
            yaw = math.atan2(2.0 * (q.w * q.z + q.x * q.y), 1.0 - 2.0 * (q.y * q.y + q.z * q.z))
            return np.array([p.x, p.y, p.z, yaw])

        yield h, client, tool
