"""End to end on the simulated UR5: hand-guide the tool along +X while teach_node records it, mark a keyframe,
stop and save; the program is a YAML file under ~/.ros that lists, shows and round-trips; the command line
answers with the services' reasons; refusals change nothing."""

from __future__ import annotations

import os
import subprocess

import pytest

pytest.importorskip("compliant_control_msgs.srv", reason="needs devel/setup.bash (make test sources it)")

from compliant_control_msgs.srv import (
    Guide,
    ListPrograms,
    ProgramCommand,
    PushEEF,
    PushEEFRequest,
    RecordProgram,
)
from harness.launch import run_launch
from harness.observed import SimArm
from harness.waiting import wait_until
from std_srvs.srv import Trigger
from teach.program import ProgramStore


def test_record_a_hand_guided_push_save_list_show_and_delete(ros_node, tmp_path):
    rospy = ros_node
    home = tmp_path / "home"
    home.mkdir()
    env = {**os.environ, "HOME": str(home)}  # programs_dir's default: ~/.ros/compliant_programs
    with run_launch("ur5_custom", "sim.launch", env=env) as h:
        for service in ("/teach/record", "/teach/stop", "/contact_control_node/guide", "/mujoco_driver/push"):
            h.wait_for_service(service, timeout=40)
        record = rospy.ServiceProxy("/teach/record", RecordProgram)
        stop = rospy.ServiceProxy("/teach/stop", Trigger)
        keyframe = rospy.ServiceProxy("/teach/keyframe", Trigger)
        with SimArm() as arm:
            pose, joints = arm.pose, arm.joints
            # Refusals first: nothing to stop, a bad name.
            assert not stop().success
            answer = record(name="../x", keep_bag=False, overwrite=False)
            assert not answer.success and "program name" in answer.message
            assert not keyframe().success

            assert rospy.ServiceProxy("/contact_control_node/guide", Guide)(enable=True, axes=[]).success
            answer = record(name="push_x", keep_bag=True, overwrite=False)
            assert answer.success and "recording 'push_x' at 50 Hz" in answer.message, answer.message
            again = record(name="other", keep_bag=False, overwrite=False)
            assert not again.success and "already recording 'push_x'" in again.message
            start_x = pose.last().pose.position.x
            push = PushEEFRequest(duration=0.5)
            push.wrench.force.x = 6.0
            assert rospy.ServiceProxy("/mujoco_driver/push", PushEEF)(push).success
            wait_until(lambda: pose.last().pose.position.x - start_x > 0.01, 10, "the guided tool to move")
            assert keyframe().success
            wait_until(lambda: pose.last().pose.position.x - start_x > 0.03, 10, "the tool to go on")
            wait_until(arm.at_rest, 10, "the arm at rest")
            end_x = pose.last().pose.position.x
            saved = stop()
            assert saved.success and "push_x: robot" in saved.message, saved.message
            assert rospy.ServiceProxy("/contact_control_node/guide", Guide)(enable=False, axes=[]).success

            folder = home / ".ros" / "compliant_programs"
            assert (folder / "push_x.yaml").exists() and (folder / "push_x.bag").exists()
            program = ProgramStore(str(folder)).load("push_x")
            first, last = program.waypoints[0], program.waypoints[-1]
            print(f"\n{program.summary()}; tool {first.position} -> {last.position}")
            assert program.robot and program.joint_names == tuple(joints.last().name)
            assert last.position[0] - first.position[0] == pytest.approx(end_x - start_x, abs=0.003)
            assert abs(last.position[1] - first.position[1]) < 0.003
            assert sum(w.keyframe for w in program.waypoints) == 1
            assert max(w.wrench[0] for w in program.waypoints) > 3.0  # the push, as the sensor read it
            assert 2 <= len(program.waypoints) < program.samples  # simplified

            listed = rospy.ServiceProxy("/teach/list", ListPrograms)()
            assert listed.names == ["push_x"] and listed.summaries[0].startswith("push_x: robot")
            shown = rospy.ServiceProxy("/teach/show", ProgramCommand)(name="push_x")
            assert shown.success and "waypoints:" in shown.message
            missing = rospy.ServiceProxy("/teach/show", ProgramCommand)(name="nope")
            assert not missing.success and "no program 'nope'" in missing.message
            assert "push_x" in missing.message  # the programs there

            # The command line: the same answers.
            out = subprocess.run(["rosrun", "teach", "teach", "list"], capture_output=True, text=True,
                                 timeout=60)
            assert out.returncode == 0 and "push_x: robot" in out.stdout, out.stdout + out.stderr
            out = subprocess.run(["rosrun", "teach", "teach", "delete", "push_x"], capture_output=True,
                                 text=True, timeout=60)
            assert out.returncode == 0 and "deleted" in out.stdout, out.stdout + out.stderr
            assert not (folder / "push_x.yaml").exists() and not (folder / "push_x.bag").exists()
            out = subprocess.run(["rosrun", "teach", "teach", "delete", "push_x"], capture_output=True,
                                 text=True, timeout=60)
            assert out.returncode == 1 and "no program 'push_x'" in out.stderr
        h.stop()
