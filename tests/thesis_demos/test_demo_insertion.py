"""The seventh demonstration (peg in hole): its verdict on synthetic task runs, its scene, and the report a
second launch adds to (no ROS)."""

import math

import numpy as np
import pytest
import yaml
from thesis_demos.analysis import Verdict
from thesis_demos.insertion import TaskRecording, judge_task
from thesis_demos.report import markdown
from thesis_demos.scenarios import SCENARIOS, by_name

HOLE = (0.6027, 0.1081, 0.15, math.radians(-1.4))  # x, y, plate top, yaw


def _run(outcome="succeeded", tip_z=HOLE[2] - 0.0152, times=(1.6, 0.8, 5.1, 0.3, 2.8), force=11.4,
         torque=0.05) -> TaskRecording:
    path = np.array([[0.6, 0.109, 0.2], [0.6, 0.109, HOLE[2]], [HOLE[0], HOLE[1], tip_z]])
    return TaskRecording(outcome, "inserted 15 mm" if outcome == "succeeded" else "stuck before 15 mm",
                         ["approach", "touch", "search", "seat", "insert"][:len(times)], list(times), force,
                         torque, HOLE, (0.6, 0.109), pose_t=np.arange(3.0), pose=path)


def test_a_task_inserted_deep_enough_in_time_and_under_the_peaks_passes_and_says_where_the_hole_was():
    demo = by_name(["peg_in_hole"])[0].task
    verdict = judge_task(demo, _run())
    assert verdict.passed, verdict.summary
    assert verdict.summary.startswith("hole +2.7, -0.9 mm and -1.4 deg from nominal, not told to the task")
    assert "15.2 mm deep (>= 15)" in verdict.summary and "seat 0.3 s" in verdict.summary
    assert verdict.figures["depth [mm]"] == pytest.approx(15.2)


@pytest.mark.parametrize(("run", "says"), [
    (_run(outcome="failed"), "task failed: stuck before 15 mm"),
    (_run(tip_z=HOLE[2] - 0.012), "12.0 mm deep (>= 15)"),
    (_run(times=(1.6, 0.8, 30.0, 10.0, 5.0)), "47.4 s (<= 45)"),
    (_run(force=25.5), "peak |F| 25.5 N (<= 25)"),
    (_run(torque=2.1), "peak |T| 2.10 Nm (<= 2)"),
])
def test_each_requirement_fails_the_demonstration_alone(run, says):
    verdict = judge_task(by_name(["peg_in_hole"])[0].task, run)
    assert not verdict.passed and says in verdict.summary


def test_peg_in_hole_is_the_seventh_demonstration_in_a_scene_of_its_own():
    assert [s.name for s in SCENARIOS][6] == "peg_in_hole"
    scene = dict(by_name(["peg_in_hole"])[0].scene)
    assert scene["fixture"] == "hole" and scene["tool"] == "peg" and int(scene["hole_seed"]) >= 0
    assert [s.name for s in SCENARIOS if s.scene] == ["peg_in_hole", "curved_surface"]


def test_a_second_run_adds_its_sections_to_the_report(tmp_path):
    data = tmp_path / "report.yaml"
    first = [(by_name(["follower_z"])[0], Verdict(True, "moved at F/b", {"v [m/s]": 0.17}), "follower_z.png")]
    markdown("ur5", first, 60.0, str(data))
    second = [(by_name(["peg_in_hole"])[0], Verdict(False, "stuck", {}), "peg_in_hole.png")]
    text = markdown("ur5", second, 30.0, str(data), append=True)
    assert "1 of 2 passed, in 90 s of wall time." in text
    assert text.index("Follower law on Z") < text.index("Peg in hole")
    assert "![peg_in_hole](peg_in_hole.png)" in text
    # A new first run starts the report over.
    again = markdown("ur5", first, 10.0, str(data))
    assert "1 of 1 passed, in 10 s" in again and len(yaml.safe_load(data.read_text())["sections"]) == 1
