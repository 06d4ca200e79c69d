"""Faults stay local in one world (mujoco_driver README, *Cells*): the UR5 (`left`) and the Panda (`right`)
served by one `mujoco_cell`; the left arm's control_stack killed (SIGKILL) while it jogs at 20 mm/s and the
right arm runs a contact move. The left arm stops as it does alone (its command_timeout), and the right arm's
follower and spring demonstrations pass meanwhile, although one loop steps both arms."""

from __future__ import annotations

import os
import signal
import subprocess

import numpy as np
import pytest

pytest.importorskip("compliant_control_msgs.msg", reason="needs devel/setup.bash (make test sources it)")

from compliant_control_msgs.msg import ContactControlStatus
from geometry_msgs.msg import PoseStamped
from harness.launch import run_node
from harness.process import node_pid
from harness.two_arms import Jogger, position, standing_still
from harness.waiting import Collector, wait_until
from rospkg import RosPack

pytestmark = pytest.mark.cell


def test_killing_one_arms_stack_halts_it_and_the_other_passes_its_demonstrations(ros_node, tmp_path):
    rospy = ros_node
    path = RosPack().get_path("mujoco_driver") + "/config/cells/ur5_panda.yaml"
    with run_node("mujoco_driver", "cell", args=[path, "--wait"]) as cell:
        for ns in ("left", "right"):
            cell.wait_for_service(f"/{ns}/configure_laws", timeout=120)
        left = Collector("/left/mujoco_driver/eef_pose", PoseStamped)
        left.wait_for(5, timeout=20)
        jogger = Jogger(rospy, "left", "left/base_link")

        env = dict(os.environ, ROS_NAMESPACE="/right", ROS_HOME=str(tmp_path))
        demos = subprocess.Popen(["rosrun", "thesis_demos", "run_demos", "--robot", "panda", "--only",
                                  "follower_z", "spring_x", "--output", str(tmp_path)],
                                 env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
        try:
            # The kill lands while the right arm runs a contact move: a world held for the dead stack would
            # starve the right's contact_control of wrenches (its stale timeout) and end the move.
            def right_moving() -> bool:
                jogger.jog(0.05)
                status = rospy.wait_for_message("/right/contact_control_node/status", ContactControlStatus, 5)
                return status.move_active
            wait_until(right_moving, 60, "the right arm's first contact move")
            jogger.jog(0.5)
            killed_at = position(left)
            os.kill(node_pid("/left/control_stack"), signal.SIGKILL)
            jogger.jog(1.0)  # the keyboard keeps sending: nothing is left to carry it out
            left.clear()
            wait_until(lambda: standing_still(left), 15, "the left arm to stop")
            coast = float(np.linalg.norm(position(left) - killed_at))
            print(f"left arm: {coast * 1e3:.1f} mm from the kill to standstill")
            assert coast < 0.01, f"the left arm ran {coast * 1e3:.1f} mm after its stack died"
            out, _ = demos.communicate(timeout=300)
        finally:
            if demos.poll() is None:
                demos.kill()
        assert demos.returncode == 0, out[-3000:]
        assert "[PASS] follower_z" in out and "[PASS] spring_x" in out, out[-3000:]
        assert cell.proc.poll() is None, "the cell's driver lives on"
