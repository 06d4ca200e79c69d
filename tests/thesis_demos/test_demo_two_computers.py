"""The stack on one computer, the robot on another (README, *Two computers*): the simulated UR5 speaking as
ur_robot_driver and the ROS master run in a network namespace of their own, reached over a veth pair;
`make demo`'s `--master` starts only ur5_custom's hardware.launch and the demonstrations on this side."""

import os
import pathlib
import subprocess
import xmlrpc.client

import pytest
from harness.netns import can_make_links, second_computer
from harness.process import stop_process_group
from harness.ros_env import free_port
from harness.waiting import wait_until

ROOT = pathlib.Path(__file__).resolve().parents[2]
WITH_ENV = str(ROOT / "scripts/with_env")

pytestmark = [pytest.mark.e2e, pytest.mark.cell]


def _env(ip: str, master: str, home: pathlib.Path) -> dict[str, str]:
    """A computer's ROS environment: its own address, the master's URI."""
    env = dict(os.environ, ROS_MASTER_URI=master, ROS_IP=ip, ROS_HOME=str(home))
    env.pop("ROS_HOSTNAME", None)
    return env


def _answers(uri: str) -> bool:
    try:
        return xmlrpc.client.ServerProxy(uri).getSystemState("/test")[0] == 1
    except OSError:
        return False


@pytest.mark.skipif(bool(can_make_links()), reason=can_make_links() or "-")
def test_the_demonstrations_pass_with_the_driver_on_another_computer(tmp_path):
    """Follower and surface following pass through hardware.launch while the driver and the master are only
    reachable over the link; the stack's traffic crossed it (megabytes: 125 Hz joint states and wrenches)."""
    with second_computer() as link:
        port = free_port()
        master = f"http://{link.there}:{port}"
        robot = link.run_there(
            [WITH_ENV, "roslaunch", "-p", str(port), "mujoco_driver", "emulated_robot.launch",
             "robot_package:=ur5_custom", "profile:=ur_robot_driver"],
            env=_env(link.there, master, tmp_path / "robot_home"),
            stdout=open(tmp_path / "robot.log", "w"), stderr=subprocess.STDOUT,
        )
        try:
            def up() -> bool:
                assert robot.poll() is None, (tmp_path / "robot.log").read_text()[-3000:]
                return _answers(master)

            wait_until(up, 60.0, "the master over the link")
            received = link.bytes_received()
            demo = [WITH_ENV, "python", str(ROOT / "scripts/demo"), "--robot", "ur5", "--driver",
                    "ur_robot_driver", "--master", master, "--only", "follower_z", "surface_following",
                    "--bias-map", "none", "--output", str(tmp_path / "out")]
            run = subprocess.run(demo, env=_env(link.here, master, tmp_path / "home"), capture_output=True,
                                 text=True, timeout=400, check=False)
            received = link.bytes_received() - received
        finally:
            stop_process_group(robot)
    out = run.stdout + run.stderr
    assert run.returncode == 0, out[-4000:] + (tmp_path / "robot.log").read_text()[-3000:]
    assert f"runs with the master {master}: hardware.launch and the demonstrations start here, reached at " \
           f"{link.here}" in run.stdout
    assert "[PASS] follower_z" in run.stdout and "[PASS] surface_following" in run.stdout
    assert received > 5_000_000, f"only {received} bytes came over the link"


def test_a_master_that_does_not_answer_is_named_before_anything_starts(tmp_path):
    port = free_port()
    demo = [WITH_ENV, "python", str(ROOT / "scripts/demo"), "--robot", "ur5", "--driver", "ur_robot_driver",
            "--master", f"http://127.0.0.1:{port}", "--output", str(tmp_path)]
    run = subprocess.run(demo, env=_env("127.0.0.1", "", tmp_path), capture_output=True, text=True,
                         timeout=120, check=False)
    assert run.returncode == 2
    assert f"no ROS master answers at http://127.0.0.1:{port}" in run.stderr
    assert not (tmp_path / "launch.log").exists()
