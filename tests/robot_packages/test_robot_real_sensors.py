"""The Panda as a franka_ros user runs it, against the emulated franka_ros with the errors fitted from a
real Panda's F_ext: panda_custom's driver configuration sets franka_state_controller's publish rate,
contact_control measures the estimate's noise floor while zeroing and refuses a force limit the estimate
cannot resolve."""

from __future__ import annotations

import pathlib

import numpy as np
import pytest
import yaml

pytest.importorskip("controller_manager_msgs.srv", reason="needs devel/setup.bash (make test sources it)")

from compliant_control_msgs.msg import ContactControlStatus
from compliant_control_msgs.srv import ConfigureLaws, ConfigureLawsRequest
from geometry_msgs.msg import WrenchStamped
from harness.launch import run_launch
from harness.waiting import Collector, wait_until

ROOT = pathlib.Path(__file__).resolve().parents[2]
FRANKA_CONFIG = ROOT / "src" / "panda_custom" / "config" / "franka_ros.yaml"


def test_the_panda_bring_up_rate_reaches_the_driver_and_the_noise_floor_refuses_a_limit_below_it(ros_node):
    rospy = ros_node
    args = {"robot_package": "panda_custom", "profile": "franka_ros", "driver_config": str(FRANKA_CONFIG)}
    wrench = Collector("/franka_state_controller/F_ext", WrenchStamped)
    status = Collector("/contact_control_node/status", ContactControlStatus)
    try:
        with run_launch("mujoco_driver", "emulated_robot.launch", args=args) as driver:
            driver.wait_for_topic("/franka_state_controller/joint_states", timeout=40)
            # panda_custom/config/franka_ros.yaml sets 100 Hz (franka_control's default is 30 Hz).
            wrench.wait_for(200, timeout=20)
            stamps = np.array([m.header.stamp.to_sec() for m in wrench.msgs[-150:]])
            rate = 1.0 / np.median(np.diff(stamps))
            assert rate == pytest.approx(100.0, rel=0.05)
            with run_launch("panda_custom", "hardware.launch") as stack:
                stack.wait_for_service("/configure_laws", timeout=40)
                wait_until(lambda: status.last() is not None and len(status.last().noise_std) == 6, 40,
                           "contact_control's noise floor on ~status")
                floor = status.last()
                # The estimate's noise at rest, as fitted from the real Panda (0.12-0.30 N total): not zero.
                assert 0.02 < max(floor.noise_std[:3]) < 1.0, floor.noise_std
                least = 5.0 * max(floor.noise_filtered[:3])
                configure = rospy.ServiceProxy("/configure_laws", ConfigureLaws)
                req = ConfigureLawsRequest()
                req.z.law, req.z.damping, req.z.force_limit, req.z.velocity = 3, 30.0, 0.2 * least, -0.01
                answer = configure(req)
                assert not answer.success and answer.code == -2
                assert "below what the sensor resolves" in answer.message and "axis z" in answer.message
                req.z.force_limit = 2.0 * least
                answer = configure(req)
                assert answer.success, answer.message
                stack.stop()
            driver.stop()
    finally:
        wrench.close()
        status.close()
        # The driver configuration was loaded at the root of this session's master and would outlive the
        # launch: later tests' emulated franka would read 100 Hz (or 30 N reflexes) from it.
        for key in yaml.safe_load(FRANKA_CONFIG.read_text()):
            if rospy.has_param(f"/{key}"):
                rospy.delete_param(f"/{key}")
