"""Two robots on one master (README, *Namespaces*): the simulated UR5 as `left` and the Panda as `right`, each
sim.launch with `ns` and `tf_prefix`. No topic, service, parameter, node or tf frame is shared, each arm jogs
on its own commands only, and one arm's dead stack leaves the other's demonstrations passing."""

from __future__ import annotations

import contextlib
import os
import signal
import subprocess

import numpy as np
import pytest

pytest.importorskip("compliant_control_msgs.msg", reason="needs devel/setup.bash (make test sources it)")

from compliant_control_msgs.msg import ContactControlStatus
from geometry_msgs.msg import PoseStamped
from harness.launch import run_launch
from harness.process import node_pid
from harness.two_arms import SHARED, Jogger, master, standing_still
from harness.two_arms import position as _position
from harness.waiting import Collector, wait_until
from tf2_msgs.msg import TFMessage

pytestmark = pytest.mark.cell

ROBOTS = {"left": ("ur5_custom", "base_link"), "right": ("panda_custom", "panda_link0")}


def _ours(node: str) -> bool:
    return any(node.startswith(f"/{ns}/") for ns in ROBOTS)


def _nodes() -> set[str]:
    publishers, subscribers, services = master().getSystemState("/test")[2]
    return {n for _, nodes in [*publishers, *subscribers, *services] for n in nodes}


def _names_of_our_nodes() -> set[str]:
    """Every topic and service a node of the two stacks publishes, subscribes or serves."""
    publishers, subscribers, services = master().getSystemState("/test")[2]
    return {name for name, nodes in [*publishers, *subscribers, *services] if any(_ours(n) for n in nodes)}


def test_two_robots_share_no_name_and_jog_apart(ros_node):
    rospy = ros_node
    params_before, nodes_before = set(master().getParamNames("/test")[2]), _nodes()
    with contextlib.ExitStack() as stack:
        launched = {ns: stack.enter_context(run_launch(robot, "sim.launch", args={"ns": ns, "tf_prefix": ns}))
                    for ns, (robot, _) in ROBOTS.items()}
        for ns, h in launched.items():
            h.wait_for_service(f"/{ns}/configure_laws", timeout=90)
            h.wait_for_service(f"/{ns}/named_poses/move_to", timeout=60)
        tf = Collector("/tf", TFMessage)
        poses = {ns: Collector(f"/{ns}/mujoco_driver/eef_pose", PoseStamped) for ns in ROBOTS}
        for c in (tf, *poses.values()):
            c.wait_for(5, timeout=20)

        names = _names_of_our_nodes()
        loose = sorted(n for n in names if n not in SHARED and not _ours(n))
        assert not loose, f"names of the two stacks outside their namespaces: {loose}"
        params = set(master().getParamNames("/test")[2]) - params_before
        loose = sorted(p for p in params
                       if p not in SHARED and not _ours(p) and not p.startswith("/roslaunch"))
        assert not loose, f"parameters outside the namespaces: {loose}"
        loose = sorted(n for n in _nodes() - nodes_before if not _ours(n))
        assert not loose, f"nodes outside the namespaces: {loose}"
        frames = {name for msg in tf.wait_for(50, timeout=20) for t in msg.transforms
                  for name in (t.header.frame_id, t.child_frame_id)}
        tf.close()
        assert frames and all(f.split("/")[0] in ROBOTS for f in frames), sorted(frames)
        assert {f.split("/")[0] for f in frames} == set(ROBOTS)
        for ns, (_, base) in ROBOTS.items():  # the driver's and contact_control's frames too
            assert poses[ns].last().header.frame_id.startswith(f"{ns}/")
            status = Collector(f"/{ns}/contact_control_node/status", ContactControlStatus)
            assert status.wait_for(1, timeout=10)[0].header.frame_id == f"{ns}/{base}"
            status.close()

        # Jog each arm in turn, the left with its frame's tf name, the right with the bare name: only the
        # jogged arm moves.
        for ns, frame in (("left", "left/base_link"), ("right", "panda_link0")):
            for c in poses.values():  # the previous jog's arm has stopped (its stream's timeout) before
                c.clear()
                wait_until(lambda c=c: standing_still(c), 15, "the arms to stand still")
            start = {n: _position(c) for n, c in poses.items()}
            jogger = Jogger(rospy, ns, frame)
            jogger.jog(1.0)
            jogger.close()
            moved = {n: float(np.linalg.norm(_position(c) - start[n])) for n, c in poses.items()}
            other = next(n for n in ROBOTS if n != ns)
            assert moved[ns] > 0.01, f"{ns} moved {moved[ns] * 1e3:.1f} mm on its 20 mm jog"
            assert moved[other] < 0.001, f"{other} moved {moved[other] * 1e3:.1f} mm on {ns}'s jog"


def test_killing_one_robots_stack_halts_it_and_the_other_passes_its_demonstrations(ros_node, tmp_path):
    """Faults stay local: the left arm's control_stack killed (SIGKILL) while it jogs at 20 mm/s, the left
    arm stops as it does alone (its driver's command_timeout), and the right arm's follower and spring
    demonstrations pass meanwhile, run in its namespace."""
    rospy = ros_node
    with contextlib.ExitStack() as stack:
        launched = {ns: stack.enter_context(run_launch(robot, "sim.launch", args={"ns": ns, "tf_prefix": ns}))
                    for ns, (robot, _) in ROBOTS.items()}
        for ns, h in launched.items():
            h.wait_for_service(f"/{ns}/configure_laws", timeout=90)
        left = Collector("/left/mujoco_driver/eef_pose", PoseStamped)
        left.wait_for(5, timeout=20)
        jogger = Jogger(rospy, "left", "left/base_link")
        jogger.jog(0.5)
        killed_at = _position(left)
        os.kill(node_pid("/left/control_stack"), signal.SIGKILL)
        jogger.jog(1.0)  # the keyboard keeps sending: nothing is left to carry it out

        # The driver first waits for the dead stack (lockstep_wait, wall time), then its command_timeout
        # (0.25 s simulated) stops the arm, as when the stack dies alone.
        left.clear()
        wait_until(lambda: standing_still(left), 15, "the left arm to stop")
        coast = float(np.linalg.norm(_position(left) - killed_at))
        print(f"left arm: {coast * 1e3:.1f} mm from the kill to standstill")
        assert coast < 0.01, f"the left arm ran {coast * 1e3:.1f} mm after its stack died"

        env = dict(os.environ, ROS_NAMESPACE="/right", ROS_HOME=str(tmp_path))
        demos = ["rosrun", "thesis_demos", "run_demos", "--robot", "panda", "--only", "follower_z",
                 "spring_x", "--output", str(tmp_path)]
        run = subprocess.run(demos, env=env, capture_output=True, text=True, timeout=300, check=False)
        assert run.returncode == 0, run.stdout[-3000:] + run.stderr[-3000:]
        assert "[PASS] follower_z" in run.stdout and "[PASS] spring_x" in run.stdout
        assert launched["right"].proc.poll() is None and launched["left"].proc.poll() is None
