"""End to end on the simulated arms: hand-guiding (`~guide`) gives way to a push and leaves the arm at rest
after it, and contact_control's `~events` report touch, release, force limit and move ended.

The UR5 runs the default single process (control_stack), the Panda the two-node layout."""

from __future__ import annotations

import contextlib

import numpy as np
import pytest

pytest.importorskip("compliant_control_msgs.srv", reason="needs devel/setup.bash (make test sources it)")

from compliant_control_msgs.msg import AxisLaw, ContactEvent
from compliant_control_msgs.srv import ConfigureLaws, ConfigureLawsRequest, Guide, PushEEF, PushEEFRequest
from harness.launch import run_launch
from harness.observed import SimArm
from harness.waiting import Collector, wait_until

PUSH = 6.0  # [N] along +X of the base: 6 / 50 (guide_damping_linear) = 0.12 m/s while it lasts


@pytest.mark.parametrize("robot, single_process", [("ur5_custom", True), ("panda_custom", False)])
def test_guide_gives_way_to_a_push_rests_after_it_and_events_tell_what_happened(ros_node, robot,
                                                                                 single_process):
    rospy = ros_node
    with run_launch(robot, "sim.launch", args={"single_process": str(single_process).lower()}) as h:
        h.wait_for_topic("/mujoco_driver/eef_pose", timeout=40)
        for service in ("/contact_control_node/guide", "/mujoco_driver/push", "/configure_laws"):
            h.wait_for_service(service, timeout=40)
        guide = rospy.ServiceProxy("/contact_control_node/guide", Guide)
        events_topic = Collector("/contact_control_node/events", ContactEvent)
        with SimArm() as arm, contextlib.closing(events_topic) as events:
            pose, status, tip, at_rest = arm.pose, arm.status, arm.tip, arm.at_rest

            answer = guide(enable=True, axes=[])
            assert answer.success, answer.message
            assert "hand-guiding on" in answer.message
            wait_until(lambda: status.last().guiding, 5, "~status to show guiding")
            start = tip()
            push = PushEEFRequest(duration=0.5)
            push.wrench.force.x = PUSH
            assert rospy.ServiceProxy("/mujoco_driver/push", PushEEF)(push).success
            wait_until(lambda: tip()[0] - start[0] > 0.01, 10, "the tool to follow the push along +X")
            wait_until(lambda: any(e.type == ContactEvent.RELEASE for e in events.msgs), 10, "the release")
            wait_until(at_rest, 10, "the arm to come to rest after the push")
            rested = tip()
            pose.clear()
            pose.wait_for(100, timeout=10)  # the next 100 poses (0.2 s at 500 Hz): still there
            drift = max(np.linalg.norm(np.array([m.pose.position.x, m.pose.position.y, m.pose.position.z])
                                       - rested) for m in pose.msgs)
            moved = rested - start
            print(f"\n{robot}: guided {moved[0] * 1e3:.1f} mm along +X by a {PUSH:g} N push "
                  f"(sideways {np.linalg.norm(moved[1:]) * 1e3:.1f} mm), drift at rest {drift * 1e3:.2f} mm")
            assert moved[0] > 0.02, moved
            assert np.linalg.norm(moved[1:]) < 0.25 * moved[0], moved
            assert drift < 1e-3, drift
            kinds = [e.type for e in events.msgs]
            assert kinds[:2] == [ContactEvent.TOUCH, ContactEvent.RELEASE], kinds
            touch = events.msgs[0]
            assert touch.type_name == "touch" and touch.wrench.force.x > 2.5
            assert touch.pose.header.frame_id and abs(touch.pose.pose.position.x - start[0]) < 0.05

            # Off: the arm stays at rest, ~status no longer guides, the move's end is an event.
            answer = guide(enable=False, axes=[])
            assert answer.success and "off" in answer.message, answer.message
            wait_until(lambda: not status.last().guiding, 5, "~status to stop showing guiding")
            wait_until(lambda: events.msgs[-1].type == ContactEvent.MOVE_ENDED, 5, "the move-ended event")
            assert "hand-guiding switched off" in events.msgs[-1].message

            # A contact move: guiding is refused with the reason; the move ends on its force limit on the
            # block under the tool (TOUCH, FORCE_LIMIT, then MOVE_ENDED, where it touched).
            req = ConfigureLawsRequest()
            req.z = AxisLaw(law=AxisLaw.COMPLIANT_MOVE, velocity=-0.015, force_limit=8.0)
            answer = rospy.ServiceProxy("/configure_laws", ConfigureLaws)(req)
            assert answer.success, answer.message
            refused = guide(enable=True, axes=["x"])
            assert not refused.success and "a contact move is running" in refused.message, refused.message
            events.clear()

            def kinds() -> list[tuple[str, str]]:
                return [(e.type_name, e.message) for e in list(events.msgs)]

            try:  # the end on the block's force limit (CI once saw a move_ended with fewer than 3 events)
                wait_until(lambda: any(k == "move_ended" and "limit" in m for k, m in kinds()), 30,
                           "the compliant move to end on the block's force limit")
            except AssertionError as exc:
                raise AssertionError(f"{exc}; events since the request: {kinds()}") from None
            ended = next(i for i, (k, m) in enumerate(kinds()) if k == "move_ended" and "limit" in m)
            assert ended >= 2 and [k for k, _ in kinds()[ended - 2: ended + 1]] == [
                "touch", "force_limit", "move_ended"], kinds()
            limit = events.msgs[ended - 1]
            assert abs(limit.wrench.force.z) >= 8.0 and "limit" in limit.message, limit
            assert limit.pose.pose.position.z < start[2] - 0.05  # down on the block, 7 cm below the start
        h.stop()
