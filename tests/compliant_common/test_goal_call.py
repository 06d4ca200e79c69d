"""compliant_common.goal_call: one action goal, its feedback and result, with no transition lost."""

from __future__ import annotations

import threading

import actionlib
from compliant_common.goal_call import GoalCall


class _Handle:
    """A goal handle that is already done."""

    def __init__(self, result: str) -> None:
        self._result = result

    def __eq__(self, other: object) -> bool:
        return other is self

    __hash__ = object.__hash__

    def get_comm_state(self) -> int:
        return actionlib.CommState.DONE

    def get_result(self) -> str:
        return self._result


class _RacingClient:
    """A client whose server answers before send_goal returns: the transition arrives from another thread
    while the caller has not got the handle yet (what makes SimpleActionClient log 'a goal handle that we're
    not tracking' and drop it)."""

    def send_goal(self, goal, transition_cb, feedback_cb):
        handle = _Handle(f"done: {goal}")
        early = threading.Thread(target=transition_cb, args=(handle,), daemon=True)
        early.start()
        early.join(0.2)  # the status thread gets there first (it blocks on GoalCall's lock)
        return handle


def test_a_result_that_arrives_before_send_goal_returns_is_not_lost() -> None:
    results = []
    call = GoalCall(_RacingClient(), "g1", done_cb=results.append)
    assert call.wait(5.0), "the early DONE transition was dropped"
    assert call.result() == "done: g1" and results == ["done: g1"]


def test_goals_in_a_row_each_get_their_feedback_and_result(ros_node) -> None:
    """Thirty goals one after another on a real server (the demonstrations' replays at 1 x, 2 x, pressed),
    and a cancelled one that says where it stopped."""
    from compliant_control_msgs.msg import (
        ReplayProgramAction,
        ReplayProgramFeedback,
        ReplayProgramGoal,
        ReplayProgramResult,
    )

    ns = "/goal_call_test/replay"

    def execute(goal: ReplayProgramGoal) -> None:
        server.publish_feedback(ReplayProgramFeedback(state=f"replaying {goal.name}"))
        if goal.name == "forever":
            while not server.is_preempt_requested() and not ros_node.is_shutdown():
                threading.Event().wait(0.01)
            server.set_preempted(ReplayProgramResult(success=False, message="cancelled at 40%"))
            return
        server.set_succeeded(ReplayProgramResult(success=True, message=f"replayed {goal.name}"))

    server = actionlib.SimpleActionServer(ns, ReplayProgramAction, execute, auto_start=False)
    server.start()
    client = actionlib.ActionClient(ns, ReplayProgramAction)
    assert client.wait_for_server(ros_node.Duration(10.0))
    for i in range(30):
        feedback: list[str] = []
        call = GoalCall(client, ReplayProgramGoal(name=f"p{i}"),
                        lambda fb, seen=feedback: seen.append(fb.state))
        assert call.wait(10.0), f"goal {i}: no result"
        assert call.result().message == f"replayed p{i}"
        assert feedback in ([], [f"replaying p{i}"])  # feedback may be dropped, never another goal's
    call = GoalCall(client, ReplayProgramGoal(name="forever"))
    assert not call.wait(0.2)
    call.cancel()
    assert call.wait(10.0) and call.result().message == "cancelled at 40%"
