"""A cell (mujoco_driver README, *Cells*): the UR5 as `left` and the Panda as `right` in one MuJoCo world, one
`mujoco_cell` node serving both under their namespaces. Nothing of either stack is outside its namespace and
each arm jogs on its own commands only (the demonstrations of both at once: thesis_demos/test_demo_cell)."""

from __future__ import annotations

import numpy as np
import pytest

pytest.importorskip("compliant_control_msgs.msg", reason="needs devel/setup.bash (make test sources it)")

from geometry_msgs.msg import PoseStamped
from harness.launch import run_node
from harness.two_arms import SHARED, Jogger, master, position, standing_still
from harness.waiting import Collector, wait_until
from rospkg import RosPack

pytestmark = pytest.mark.cell

ROBOTS = {"left": ("ur5", "base_link"), "right": ("panda", "panda_link0")}
def _ours(name: str) -> bool:
    return any(name.startswith(f"/{ns}/") for ns in ROBOTS)


@pytest.fixture(scope="module")
def cell(ros_node):
    path = RosPack().get_path("mujoco_driver") + "/config/cells/ur5_panda.yaml"
    with run_node("mujoco_driver", "cell", args=[path, "--wait"]) as launched:
        for ns in ROBOTS:
            launched.wait_for_service(f"/{ns}/configure_laws", timeout=120)
            launched.wait_for_service(f"/{ns}/mujoco_driver/reset", timeout=60)
        yield launched


def test_one_world_serves_each_arm_under_its_name_and_each_jogs_alone(cell, ros_node):
    rospy = ros_node
    publishers, subscribers, services = master().getSystemState("/test")[2]
    nodes = {n for _, ns in [*publishers, *subscribers, *services] for n in ns}
    assert "/mujoco_cell" in nodes, sorted(nodes)
    assert not any(n.endswith("/mujoco_driver") for n in nodes), sorted(nodes)
    served = {name for name, ns in [*publishers, *services] if "/mujoco_cell" in ns}
    loose = sorted(n for n in served
                   if n not in SHARED and not _ours(n) and not n.startswith("/mujoco_cell/"))
    assert not loose, f"the cell's names outside the arms' namespaces: {loose}"
    for ns in ROBOTS:
        assert f"/{ns}/joint_states" in served and f"/{ns}/wrench" in served
    poses = {ns: Collector(f"/{ns}/mujoco_driver/eef_pose", PoseStamped) for ns in ROBOTS}
    for ns, c in poses.items():
        assert c.wait_for(5, timeout=20)[-1].header.frame_id.startswith(f"{ns}/")

    for ns in ROBOTS:  # only the jogged arm moves: the world is shared, the commands are not
        for c in poses.values():  # the previous jog's arm has stopped (its stream's timeout) before
            c.clear()
            wait_until(lambda c=c: standing_still(c), 15, "the arms to stand still")
        start = {n: position(c) for n, c in poses.items()}
        jogger = Jogger(rospy, ns, f"{ns}/{ROBOTS[ns][1]}")
        jogger.jog(1.0)
        jogger.close()
        moved = {n: position(c) - start[n] for n, c in poses.items()}
        other = next(n for n in ROBOTS if n != ns)
        assert moved[ns][2] > 0.01, f"{ns} moved {moved[ns] * 1e3} mm on its 20 mm/s jog up"
        assert np.linalg.norm(moved[other]) < 0.001, f"{other} moved {moved[other] * 1e3} mm on {ns}'s jog"
    for c in poses.values():
        c.close()
