"""Teach by hand, end to end on the simulated UR5: with hand-guiding on, the simulated human pushes the tool
along an L (about 10 cm along +X, then 5 cm along +Y) while program_server records it; the program replays in
free space within 2 mm RMS / 5 mm max of the recorded path, at its speed and at twice it (planned within
the arm's limits)."""

from __future__ import annotations

import os
import re

import numpy as np
import pytest

pytest.importorskip("compliant_control_msgs.msg", reason="needs devel/setup.bash (make test sources it)")

import actionlib
from compliant_control_msgs.msg import ReplayProgramAction, ReplayProgramGoal
from compliant_control_msgs.srv import Guide, PushEEF, PushEEFRequest, RecordProgram
from harness.launch import run_launch
from harness.observed import SimArm
from harness.waiting import wait_until
from std_srvs.srv import Trigger
from teach.program import ProgramStore

PUSH = 6.0  # [N]: 6 / 50 (guide_damping_linear) = 12 cm/s while it lasts


def test_a_hand_guided_l_is_recorded_and_replayed_within_2_mm(ros_node, tmp_path):
    rospy = ros_node
    home = tmp_path / "home"
    with run_launch("ur5_custom", "sim.launch", env={**os.environ, "HOME": str(home)}) as h:
        for service in ("/teach/record", "/contact_control_node/guide", "/mujoco_driver/push",
                        "/named_poses/move_to_joints"):
            h.wait_for_service(service, timeout=40)
        push_eef = rospy.ServiceProxy("/mujoco_driver/push", PushEEF)
        with SimArm() as arm:

            def push(x: float, y: float, seconds: float) -> None:
                """The push, then its effect: the tool 10 mm along it (the service returns before the
                simulation applies it; on a loaded machine "not at rest" was still the last push's coasting,
                and the recording stopped before this push moved the tool), then at rest."""
                start, along = arm.tip(), np.array([x, y, 0.0]) / np.hypot(x, y)
                request = PushEEFRequest(duration=seconds)
                request.wrench.force.x, request.wrench.force.y = x, y
                assert push_eef(request).success
                wait_until(lambda: (arm.tip() - start) @ along > 0.01, 10, "the tool to follow the push")
                wait_until(arm.at_rest, 15, "the tool to come to rest after the push")

            assert rospy.ServiceProxy("/contact_control_node/guide", Guide)(enable=True, axes=[]).success
            assert rospy.ServiceProxy("/teach/record", RecordProgram)(name="l_by_hand").success
            push(PUSH, 0.0, 1.0)  # along +X
            push(0.0, PUSH, 0.5)  # then +Y
            saved = rospy.ServiceProxy("/teach/stop", Trigger)()
            assert saved.success, saved.message
            assert rospy.ServiceProxy("/contact_control_node/guide", Guide)(enable=False, axes=[]).success
            program = ProgramStore(str(home / ".ros" / "compliant_programs")).load("l_by_hand")
            legs = np.array(program.waypoints[-1].position) - np.array(program.waypoints[0].position)
            print(f"\n{program.summary()}; legs {legs[0] * 1e3:.1f} mm X, {legs[1] * 1e3:.1f} mm Y")
            assert legs[0] > 0.07 and legs[1] > 0.035 and abs(legs[2]) < 0.003, legs

            client = actionlib.SimpleActionClient("/teach/replay", ReplayProgramAction)
            assert client.wait_for_server(rospy.Duration(20.0))
            # This hand is at the arm's limits (0.12 m/s; its 1 x replay is slowed about 10 %). Twice as fast
            # is beyond them: the replay's timing is planned within them (slower where it must be), and says
            # so. The premise is checked by the 1 x replay: once in CI the recording took 60 s for this 2 s L
            # (the simulation starved, probably) and its 1 x replay needed no slowing: 2 x may then fit.
            at_limits = False
            for speed in (1.0, 2.0):
                client.send_goal(ReplayProgramGoal(name="l_by_hand", speed=speed))
                assert client.wait_for_result(rospy.Duration(90.0))
                result = client.get_result()
                print(f"replay by hand at {speed:g}x: {result.message}")
                assert result.success, result.message
                assert result.path_error_rms < 0.002 and result.path_error_max < 0.005, result.message
                # 2 x of a hand already at the arm's accelerations is slowed; 1 x at most where the hand's
                # coast stopped faster than the arm is planned to (about 10 %).
                planned = re.search(r"\(([\d.]+) s planned instead of ([\d.]+) s\)", result.message)
                if speed > 1.0:
                    assert planned is not None or not at_limits, result.message
                elif planned is not None:
                    at_limits = True
                    assert float(planned[1]) <= 1.25 * float(planned[2]), result.message
        h.stop()
