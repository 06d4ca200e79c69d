"""The executor's step logic (contact_tasks.run) in a closed loop with the pure controller: a square peg into
a chamfered hole whose position is not known, the failure branch, the ceilings, cancel and refusal."""

from __future__ import annotations

import math
import pathlib

import numpy as np
import pytest
from contact_tasks.run import CANCELLED, FAILED, SUCCEEDED, Observation, TaskRun
from contact_tasks.task_file import load_task_file, parse_task

from .hole_world import HoleWorld, TaskLoop, tool_down

PEG_IN_HOLE = pathlib.Path(__file__).resolve().parents[2] / "src/contact_tasks/tasks/peg_in_hole.yaml"
START = tool_down(0.0, 0.0, 0.01)  # 10 mm above the plate's nominal top, over the hole's nominal centre


def insert(hole: tuple[float, float], **world: object) -> tuple[TaskLoop, object]:
    loop = TaskLoop(TaskRun(load_task_file(PEG_IN_HOLE)), HoleWorld(hole=hole, **world), START)
    return loop, loop.go(60.0)


def test_the_peg_goes_in_wherever_the_hole_is_within_4_mm_of_nominal():
    rng = np.random.default_rng(7)
    offsets = [(0.0, 0.0), *(rng.uniform(-0.004, 0.004, size=(9, 2)))]
    for hole in offsets:
        loop, end = insert(tuple(hole))
        result = loop.run.result
        assert end.outcome == SUCCEEDED, (hole, end.reason)
        assert loop.pose[2, 3] < -0.0149  # 15 mm into the hole
        assert np.all(np.abs(loop.pose[:2, 3] - hole) <= 0.0002 + 1e-4)  # within the clearance
        assert result.peak_force <= 25.0 and loop.t < 45.0
        assert end.stop  # contact_control is told to stop: the arm holds


def test_a_hole_too_far_away_fails_the_search_with_its_reason_and_retracts():
    loop, end = insert((0.015, 0.0))
    assert end.outcome == FAILED
    assert end.reason == "in step 'search': the hole was not found within 6 mm (retract: retracted)"
    assert list(loop.run.result.step_times) == ["approach", "touch", "search", "retract"]
    assert loop.pose[2, 3] >= 0.02  # backed off 20 mm and more from the plate
    assert loop.run.result.peak_force < 30.0


def test_a_robot_stop_ends_the_task_at_once_with_its_reason_and_nothing_more_is_tried():
    """The driver holds the arm (jog_arm's ~robot_stop): no step can move it, not even the retract."""
    loop = TaskLoop(TaskRun(load_task_file(PEG_IN_HOLE)), HoleWorld(hole=(0.015, 0.0)), START)
    loop.stop_at = 4.0  # searching by then: the hole is out of reach
    end = loop.go(60.0)
    assert end.outcome == FAILED and end.stop
    step = loop.commands[-2].step
    assert end.reason == f"in step '{step}': the robot stopped: a protective stop"
    assert "retract" not in loop.run.result.step_times
    assert loop.t < 4.1  # at the first observation after the stop


def test_the_force_ceiling_fails_the_task_at_once_and_the_retract_runs():
    """A compliant move down would press b V = 20 N: the task's 6 N ceiling fails it and backs off."""
    hard = parse_task({
        "task": "hard", "force_ceiling": 6.0,
        "steps": {"down": {"laws": {"z": {"law": "compliant_move", "velocity": -0.01, "damping": 2000.0,
                                          "max_travel": 0.05}},
                           "exits": [{"when": "timeout", "after": 10.0, "succeed": "pressed"}]}},
    })
    loop = TaskLoop(TaskRun(hard), HoleWorld(hole=(0.02, 0.0)), START)
    end = loop.go(30.0)
    assert end.outcome == FAILED and "|F|" in end.reason
    assert "above the task's force ceiling 6 N" in end.reason
    assert loop.run.result.step_times["down"] < 5.0  # long before its timeout
    assert loop.pose[2, 3] > 0.015  # the default retract's 20 mm from the plate


def test_steps_that_lead_back_to_each_other_end_at_the_tasks_time_limit_and_retract():
    """Two steps sending the tool to each other forever: the time limit fails the task and it backs off."""
    task = parse_task({
        "task": "ping_pong", "time_limit": 3.0,
        "steps": {
            "ping": {"exits": [{"when": "timeout", "after": 0.4, "next": "pong"}]},
            "pong": {"exits": [{"when": "timeout", "after": 0.4, "next": "ping"}]},
        },
    })
    loop = TaskLoop(TaskRun(task), HoleWorld(hole=(0.02, 0.0)), START)
    end = loop.go(10.0)
    assert end.outcome == FAILED
    assert end.reason.endswith("the task ran longer than its time limit 3 s (retract: retracted)"), end.reason
    times = loop.run.result.step_times
    assert times["ping"] + times["pong"] == pytest.approx(3.0, abs=0.05)
    assert loop.pose[2, 3] > 0.025  # the retract's 20 mm above the start


def test_an_on_failure_step_runs_instead_of_the_retract_and_the_task_still_fails():
    task = parse_task({
        "task": "wait_then_lift", "on_failure": "lift",
        "steps": {
            "wait": {"exits": [{"when": "timeout", "after": 0.2, "fail": "nothing happened"}]},
            "lift": {"laws": {"z": {"law": "compliant_move", "velocity": 0.02, "damping": 1000.0,
                                    "max_travel": 0.005}},
                     "exits": [{"when": "move_ended", "succeed": "lifted"}]},
        },
    })
    loop = TaskLoop(TaskRun(task), HoleWorld(hole=(0.02, 0.0)), START)
    end = loop.go(10.0)
    assert end.outcome == FAILED and end.reason == "in step 'wait': nothing happened (lift: lifted)"
    assert loop.pose[2, 3] == pytest.approx(0.015, abs=5e-4)


def test_a_force_exit_needs_its_force_for_its_duration():
    task = parse_task({
        "task": "press",
        "steps": {"down": {
            "laws": {"z": {"law": "force_tracking", "target_force": 8.0, "damping": 2500.0,
                           "velocity": 0.01}},
            "exits": [{"when": "force", "axis": "z", "above": 7.0, "for": 0.5, "succeed": "held"},
                      {"when": "timeout", "after": 10.0, "fail": "never"}]}},
    })
    loop = TaskLoop(TaskRun(task), HoleWorld(hole=(0.02, 0.0)), START)
    end = loop.go(20.0)
    assert end.outcome == SUCCEEDED
    fz = np.array(loop.trace)[:, 4]
    t = np.array(loop.trace)[:, 0]
    first = t[np.argmax(fz > 7.0)]
    assert loop.t - first >= 0.5  # not at the first sample above 7 N


def test_cancel_and_a_refused_step_stop_the_arm_and_say_why():
    task = load_task_file(PEG_IN_HOLE)
    run = TaskRun(task)
    obs = Observation(0.0, START.copy())
    first = run.start(obs)
    assert first.step == "approach" and first.laws is not None and first.laws.z.law == 3
    end = run.cancel(Observation(1.5, START.copy()))
    assert (end.outcome, end.stop, end.reason) == (CANCELLED, True, "cancelled in step 'approach'")
    assert run.result.step_times == {"approach": 1.5}
    assert run.update(Observation(2.0, START.copy())).outcome == CANCELLED  # ended: nothing more

    run = TaskRun(task)
    run.start(obs)
    end = run.refused("z.velocity: above max_velocity_linear", Observation(0.1, START.copy()))
    assert end.outcome == FAILED and end.stop
    assert end.reason == "contact_control refused step 'approach': z.velocity: above max_velocity_linear"


def test_the_search_streams_a_spiral_reference_around_the_touch_point_in_the_tools_plane():
    loop, _ = insert((0.015, 0.0))
    refs = [(c.step, c.reference) for c in loop.commands if c.reference is not None]
    search = [r for step, r in refs if step == "search"]
    xy = np.array([r.position[:2] for r in search])
    radius = np.linalg.norm(xy - xy[0], axis=1)
    assert radius.max() == pytest.approx(0.006, abs=1e-4)
    assert np.ptp([r.position[2] for r in search]) == 0.0  # the plane of the tool's x/y: horizontal
    q = search[0].quaternion  # the tool's orientation at the step's start (pointing down)
    assert abs(q[0]) == pytest.approx(1.0) and math.isclose(q[3], 0.0, abs_tol=1e-9)


def test_each_search_reference_carries_where_the_spiral_will_be_next():
    """With a 0.1 s horizon every 20 ms: a reference's horizon is the references the search sends later."""
    loop = TaskLoop(TaskRun(load_task_file(PEG_IN_HOLE), horizon=0.1, horizon_step=0.02),
                    HoleWorld(hole=(0.015, 0.0)), START)
    loop.go(60.0)
    search = [c.reference for c in loop.commands if c.step == "search" and c.reference is not None]
    assert len(search) > 100
    first = search[10]
    assert first.horizon_step == 0.02 and len(first.horizon) == 5
    later = np.array([r.position for r in search])
    for j, (position, quaternion) in enumerate(first.horizon, start=1):
        # The loop observes every 5 cycles of 2 ms: a reference every 10 ms, 20 ms on is two later.
        assert np.allclose(position, later[10 + 2 * j], atol=1e-9)
        assert np.allclose(quaternion, search[10 + 2 * j].quaternion, atol=1e-9)
    assert np.linalg.norm(np.subtract(first.horizon[-1][0], first.position)) > 1e-4  # it moves on

