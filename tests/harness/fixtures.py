"""pytest fixtures: one private roscore and one rospy client node per test session.

rospy can initialise a node only once per process, so the master and the client are session-wide;
tests start and stop their own nodes (harness.launch) against it.
"""

from __future__ import annotations

import os
from collections.abc import Iterator

import pytest

from harness.ros_env import Master, start_master


@pytest.fixture(scope="session")
def roscore(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Master]:
    """A real roscore on a free port; ROS_MASTER_URI and ROS_HOSTNAME set for the session."""
    log_dir = str(tmp_path_factory.mktemp("ros_log"))
    master = start_master(log_dir=log_dir)
    saved = {k: os.environ.get(k) for k in ("ROS_MASTER_URI", "ROS_HOSTNAME", "ROS_IP", "ROS_LOG_DIR")}
    os.environ.update({k: master.env[k] for k in ("ROS_MASTER_URI", "ROS_HOSTNAME")})
    os.environ["ROS_LOG_DIR"] = log_dir
    os.environ.pop("ROS_IP", None)
    try:
        yield master
    finally:
        master.stop()
        for key, value in saved.items():
            if value is None:
                os.environ.pop(key, None)
            else:
                os.environ[key] = value


@pytest.fixture(scope="session")
def ros_node(roscore: Master):
    """The test process's rospy client node (initialised once); returns the rospy module."""
    import rospy

    rospy.init_node("pytest_client", anonymous=True, disable_signals=True)
    yield rospy
    rospy.signal_shutdown("pytest session finished")
