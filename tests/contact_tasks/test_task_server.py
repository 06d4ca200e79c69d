"""End to end: task_server's ~execute on the simulated UR5. A task touches the block under the tool, presses
8 N and rubs 20 mm along X (a line pattern with the path law on X and Y); the result names its steps and
peaks. Cancelled mid-rub the arm stops and the action says so; a bad task file is refused with its key and
nothing moves. Laws along the tool's axes at the step's start go straight while the tool turns. A task's body
region (ISO/TS 15066) holds on jog_arm while it runs, the robot's after."""

from __future__ import annotations

import pytest

pytest.importorskip("compliant_control_msgs.msg", reason="needs devel/setup.bash (make test sources it)")

import actionlib
import numpy as np
from compliant_control_msgs.msg import ContactControlStatus, ExecuteTaskGoal
from compliant_control_msgs.srv import MoveToNamedPose
from harness.waiting import wait_until

from .task_stack import task_stack

RUB = """
task: rub
force_ceiling: 20.0
steps:
  near:  # fast to 2 cm above the block (7 cm below the start pose)
    laws: {z: {law: compliant_move, velocity: -0.03, damping: 2000.0, force_limit: 10.0, max_travel: 0.05}}
    exits:
      - {when: touch, fail: touched early}
      - {when: move_ended, next: approach}
  approach:
    laws: {z: {law: compliant_move, velocity: -0.008, damping: 2000.0, force_limit: 10.0, max_travel: 0.05}}
    exits:
      - {when: touch, next: rub}
      - {when: move_ended, fail: no block under the tool}
  rub:
    laws:
      z: {law: force_tracking, target_force: 8.0, damping: 2000.0, velocity: 0.005}
      x: {law: path, stiffness: 5.0, damping: 0.0, max_travel: 0.01}
      y: {law: path, stiffness: 5.0, damping: 0.0, max_travel: 0.01}
    pattern: {type: line, axis: x, distance: 0.02, speed: %(speed)s}
    frame: fixed
    exits:
      - {when: pattern_done, succeed: rubbed 20 mm}
      - {when: timeout, after: 30.0, fail: too slow}
"""

TURN = """
task: turn
steps:
  move:  # 20 mm along the tool's axis while it turns 0.25 rad about its x
    law_frame: %(frame)s
    laws:
      z: {law: compliant_move, velocity: 0.01, damping: 2000.0, force_limit: 10.0, max_travel: 0.02}
      rx: {law: compliant_move, velocity: 0.125, damping: 50.0, force_limit: 2.0, max_travel: 0.25}
    exits:
      - {when: move_ended, succeed: moved}
      - {when: timeout, after: 15.0, fail: too slow}
"""

HOLD = """
task: hold
body_region: face
steps:
  wait:
    laws: {z: {law: follower, damping: 2000.0}}
    exits:
      - {when: timeout, after: 1.0, succeed: waited}
"""


def test_a_task_touches_rubs_at_a_force_and_cancels_and_refuses(ros_node):
    rospy = ros_node
    with task_stack() as (h, client, tool):
        move = rospy.ServiceProxy("/named_poses/move_to", MoveToNamedPose)
        assert move(name="start").success
        start = tool()
        feedback = []
        client.send_goal(ExecuteTaskGoal(task_yaml=RUB % {"speed": 0.005}), feedback_cb=feedback.append)
        assert client.wait_for_result(rospy.Duration(90.0))
        result = client.get_result()
        times = list(zip(result.steps, result.step_times, strict=True))
        print(f"\nrub: {result.outcome}: {result.message}; {times}, peak {result.peak_force:.1f} N")
        assert result.success and result.message == "rubbed 20 mm", result.message
        assert list(result.steps) == ["near", "approach", "rub"]
        end = tool()
        assert end[0] - start[0] == pytest.approx(0.02, abs=0.002)  # the line along X
        assert abs(end[1] - start[1]) < 0.002
        assert end[2] < start[2] - 0.05  # on the block, 7 cm below the start pose
        assert result.peak_force < 20.0
        rubbing = [f for f in feedback if f.step == "rub" and f.elapsed > feedback[0].elapsed + 1.0]
        assert rubbing and all(4.0 < f.wrench.force.z < 12.0 for f in rubbing[5:])
        assert result.end_pose.pose.position.z == pytest.approx(end[2], abs=0.002)

        # Cancelled mid-rub: the action is preempted with the step, and contact_control's move has ended.
        assert move(name="start").success
        feedback.clear()
        client.send_goal(ExecuteTaskGoal(task_yaml=RUB % {"speed": 0.002}), feedback_cb=feedback.append)
        wait_until(lambda: feedback and feedback[-1].step == "rub", 60, "the rub to begin")
        client.cancel_goal()
        assert client.wait_for_result(rospy.Duration(20.0))
        cancelled = client.get_result()
        assert client.get_state() == actionlib.GoalStatus.PREEMPTED
        assert (cancelled.outcome, cancelled.message) == ("cancelled", "cancelled in step 'rub'")
        status = rospy.wait_for_message("/contact_control_node/status", ContactControlStatus, timeout=5.0)
        assert not status.move_active

        # A bad file is refused, naming the key; nothing moves.
        before = tool()
        client.send_goal(ExecuteTaskGoal(task_yaml=(RUB % {"speed": 0.005}).replace("touch, next: rub",
                                                                                     "touch, next: rbu")))
        assert client.wait_for_result(rospy.Duration(10.0))
        refused = client.get_result()
        assert client.get_state() == actionlib.GoalStatus.ABORTED and refused.outcome == "refused"
        assert refused.message == ("<goal task_yaml>: steps.approach.exits[0].next: no step 'rbu': did you "
                                   "mean 'rub'?")
        assert np.linalg.norm(tool()[:3] - before[:3]) < 0.001
        client.send_goal(ExecuteTaskGoal(task="no_such_task"))
        assert client.wait_for_result(rospy.Duration(10.0))
        assert "no_such_task.yaml: cannot read the task file" in client.get_result().message

        # Laws along the tool's axes as they were at the step's start: the move goes straight down while the
        # tool turns; along the tool's turning axes it bends sideways.
        sideways = {}
        for frame in ("tool_at_start", "tool"):
            assert move(name="start").success
            before = tool()
            client.send_goal(ExecuteTaskGoal(task_yaml=TURN % {"frame": frame}))
            assert client.wait_for_result(rospy.Duration(30.0))
            assert client.get_result().success, client.get_result().message
            moved = tool()[:3] - before[:3]
            sideways[frame] = float(np.hypot(moved[0], moved[1]))
            assert moved[2] < -0.015, (frame, moved)
        print(f"\nsideways while turning: {sideways}")
        assert sideways["tool_at_start"] < 0.8e-3 < 1.5e-3 < sideways["tool"]

        # The task's body region holds on jog_arm while it runs; the robot's own comes back after.
        region = "/jog_arm_server/collaborative_region"
        assert rospy.get_param(region) == "hand"
        seen: list[str] = []
        client.send_goal(ExecuteTaskGoal(task_yaml=HOLD),
                         feedback_cb=lambda _: seen.append(rospy.get_param(region)))
        assert client.wait_for_result(rospy.Duration(20.0))
        assert client.get_result().success, client.get_result().message
        assert seen and set(seen) == {"face"}
        assert rospy.get_param(region) == "hand"
        h.stop()
