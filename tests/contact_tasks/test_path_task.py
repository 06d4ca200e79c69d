"""A path at a force as a task (contact_tasks.path_task) in a closed loop with the pure controller over a
plate: to the start, touch, press, along the path pressing along the tool's axis with a force per segment;
what it measures; the goals it refuses."""

from __future__ import annotations

import numpy as np
import pytest
from contact_tasks.path import PosePath
from contact_tasks.path_task import PathGoal, PathMetrics, path_task
from contact_tasks.run import FAILED, SUCCEEDED, Observation, TaskRun
from contact_tasks.task import TaskError

from .hole_world import HoleWorld, TaskLoop, tool_down

DOWN = (1.0, 0.0, 0.0, 0.0)  # tool_down's orientation: the tool's z along the base's -z
PLATE = dict(hole=(1.0, 1.0), friction=0.2)  # a plate whose hole is far away


def _run(goal: PathGoal, start=(0.0, 0.0, 0.03)) -> tuple[TaskLoop, object, PathMetrics]:
    tool = tool_down(*start)
    run = TaskRun(path_task(goal, tool), horizon=0.4, tool_frame="tool_tip")
    loop = TaskLoop(run, HoleWorld(**PLATE), tool)
    path = PosePath(goal.poses, goal.speed)
    metrics = PathMetrics(path, goal.segment_forces(path.segments))

    def watch(run: TaskRun, obs) -> None:
        if run.step_name == "follow" and run.path_point is not None and run.running:
            metrics.add(obs.t, obs.tool, obs.wrench, run.path_point.segment)

    loop.watch = watch
    return loop, loop.go(60.0), metrics


def test_the_path_is_run_pressing_each_segments_force_along_the_tools_axis():
    # planned on a plate 2 mm above the real one: the touch finds it, the force tracks it
    poses = [(0.0, 0.0, 0.002, *DOWN), (0.03, 0.0, 0.002, *DOWN), (0.03, 0.03, 0.002, *DOWN)]
    loop, end, metrics = _run(PathGoal(poses, speed=0.01, forces=(8.0, 12.0)))
    assert end.outcome == SUCCEEDED, end.reason
    assert list(loop.run.result.step_times) == ["to_start", "touch", "press", "follow"]
    assert loop.pose[:3, 3] == pytest.approx((0.03, 0.03, 0.0), abs=1e-3)  # the end, on the real plate
    summary = metrics.summary()
    assert summary["contact_fraction"] >= 0.98 and summary["lateral_error_max"] <= 0.001, summary
    assert summary["duration"] == pytest.approx(6.5, abs=0.1)  # 60 mm at 10 mm/s, 0.5 s to speed up and down
    # the plate pushes the tool along its -z: the force along the axis, pressing positive, is each target
    trace = np.asarray(loop.trace)
    t_follow = loop.t - summary["duration"]
    first = trace[(trace[:, 0] > t_follow + 1.5) & (trace[:, 0] < t_follow + 2.8), 4]
    second = trace[(trace[:, 0] > t_follow + 4.5) & (trace[:, 0] < t_follow + 5.8), 4]
    assert first.mean() == pytest.approx(8.0, abs=0.5) and second.mean() == pytest.approx(12.0, abs=0.5)
    assert summary["force_rms_error"] <= 1.5 and summary["normal_angle_max"] < 20.0


def test_a_path_above_nothing_fails_without_contact_and_backs_off():
    poses = [(0.0, 0.0, 0.06, *DOWN), (0.03, 0.0, 0.06, *DOWN)]  # 60 mm above the plate: never touched
    loop, end, _ = _run(PathGoal(poses, standoff=0.01), start=(0.0, 0.0, 0.08))
    assert end.outcome == FAILED and "no contact within 0.03 m" in end.reason, end.reason
    assert "follow" not in loop.run.result.step_times and loop.pose[2, 3] > 0.02


@pytest.mark.parametrize(("goal", "said"), [
    (PathGoal([(0, 0, 0, *DOWN)]), "path: a path needs at least two poses"),
    (PathGoal([(0, 0, 0, *DOWN), (0.1, 0, 0, *DOWN)], forces=(5.0, 6.0)), "segment_forces: 2 for 1 segments"),
    (PathGoal([(0, 0, 0, *DOWN), (0.1, 0, 0, *DOWN)], force=500.0), "outside 0.5..100 N"),
    (PathGoal([(0, 0, 0, *DOWN), (0.1, 0, 0, *DOWN)], orientation="sideways"), "orientation: 'sideways'"),
    (PathGoal([(0, 0, 0, *DOWN), (0.1, 0, 0, *DOWN)], speed=0.0), r"speed: 0 m/s is not in \(0, 0.25\]"),
])
def test_a_goal_that_cannot_be_run_is_refused_with_the_field(goal, said):
    with pytest.raises(TaskError, match=said):
        path_task(goal, tool_down(0.0, 0.0, 0.03))


def _at_press(force: float) -> tuple[TaskRun, float]:
    """A path task brought to its press step (to the start and a touch, by hand), then pressed with `force`
    along the tool's axis from then on; returns the run and when the press began [s]."""
    tool = tool_down(0.0, 0.0, 0.03)
    run = TaskRun(path_task(PathGoal([(0, 0, 0, *DOWN), (0.03, 0, 0, *DOWN)], force=10.0), tool),
                  horizon=0.4, tool_frame="tool_tip")
    t = 0.0
    run.start(Observation(t, tool))
    while run.step_name != "press":
        t += 0.01
        run.update(Observation(t, tool, touched=run.step_name == "touch"))
    return run, t


@pytest.mark.parametrize(("force", "after"), [(9.5, 1.5), (8.0, 10.0)])
def test_the_press_waits_for_the_force_to_build_up_before_the_path(force, after):
    """90 % of the target held for 1.5 s starts the path (a part that gives way builds the force slowly);
    short of it the path starts after 10 s anyway."""
    run, began = _at_press(force)
    t = began
    while run.step_name == "press" and t < began + 20.0:
        t += 0.01
        run.update(Observation(t, tool_down(0.0, 0.0, 0.0), wrench=(0.0, 0.0, -force, 0.0, 0.0, 0.0)))
    assert run.step_name == "follow"
    assert t - began == pytest.approx(after, abs=0.03)
