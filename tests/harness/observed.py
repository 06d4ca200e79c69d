"""What a test watches on the simulated stack: the tool pose, the joint states, contact_control's status."""

from __future__ import annotations

import numpy as np
from compliant_control_msgs.msg import ContactControlStatus
from geometry_msgs.msg import PoseStamped
from sensor_msgs.msg import JointState

from harness.waiting import Collector, wait_until

__all__ = ["SimArm"]


class SimArm:
    """Collectors on /mujoco_driver/eef_pose, /joint_states and contact_control's ~status. As a context
    manager it waits for a first message of each and for the sensor to be zeroed, and closes them on exit."""

    def __init__(self, status_topic: str = "/contact_control_node/status") -> None:
        self.pose = Collector("/mujoco_driver/eef_pose", PoseStamped)
        self.joints = Collector("/joint_states", JointState)
        self.status = Collector(status_topic, ContactControlStatus)

    def __enter__(self) -> SimArm:
        try:
            for c in (self.pose, self.joints, self.status):
                c.wait_for(1, timeout=20)
            ok = ContactControlStatus.SAFETY_OK
            wait_until(lambda: self.status.last().safety == ok, 20, "the sensor to be zeroed")
        except BaseException:
            self.close()
            raise
        return self

    def __exit__(self, *_exc: object) -> None:
        self.close()

    def close(self) -> None:
        for c in (self.pose, self.joints, self.status):
            c.close()

    def tip(self) -> np.ndarray:
        """The tool's position (the driver's eef pose) [m]."""
        p = self.pose.last().pose.position
        return np.array([p.x, p.y, p.z])

    def at_rest(self) -> bool:
        return bool(np.max(np.abs(self.joints.last().velocity)) < 2e-3)
