"""The eighth demonstration (a path at a force over a curved part): its verdict on synthetic runs, against
the true normal when the driver gives one; its scene; the arm's path middle from demos.yaml."""

from __future__ import annotations

import math

import numpy as np
import pytest
from thesis_demos.finishing import PathRecording, judge_path, true_angles
from thesis_demos.geometry import DemoConfigError, DemoGeometry
from thesis_demos.scenarios import SCENARIOS, by_name, curved_surface
from thesis_demos.surfaces import cylinder_path

TOP = (0.6, 0.1, 0.13)
GOOD = {"length": 0.3, "force_rms_error": 0.5, "force_max": 11.5, "contact_fraction": 1.0,
        "normal_angle_rms": 0.7, "normal_angle_max": 12.0, "lateral_error_rms": 1e-5,
        "lateral_error_max": 2e-5, "duration": 15.5}


def _run(tilt: float = 0.0, truth: bool = True, **result: float) -> PathRecording:
    """A run whose tip follows the true cylinder (3 mm off in x), its axis `tilt` [rad] off the normal."""
    true_top = (TOP[0] + 0.003, TOP[1], TOP[2])
    angles = np.linspace(-0.6, 0.6, 200)
    centre = np.array(true_top) - (0.0, 0.0, 0.25)
    tip = np.array([centre + 0.25 * np.array([math.sin(a), 0.0, math.cos(a)]) for a in angles])
    axis = np.array([[-math.sin(a + tilt), 0.0, -math.cos(a + tilt)] for a in angles])
    return PathRecording(
        outcome="succeeded", message="ran the path's 0.300 m", result={**GOOD, **result}, nominal_top=TOP,
        truth={"kind": "cylinder", "radius": 0.25, "top": list(true_top), "friction": 0.3} if truth else None,
        tip=tip, axis=axis, pose_t=np.linspace(0, 15, 200),
    )


def test_a_run_kept_normal_at_the_force_passes_and_names_the_offset():
    verdict = judge_path(by_name(["curved_surface"])[0].path, _run())
    assert verdict.passed, verdict.summary
    assert verdict.summary.startswith("part +3.0, +0.0, +0.0 mm from nominal, not told to the path")
    assert verdict.figures["angle RMS [deg]"] == pytest.approx(0.0, abs=1e-6)


@pytest.mark.parametrize(("run", "says"), [
    (_run(tilt=math.radians(4.0)), "tool to true normal RMS 4.00 deg (<= 3)"),
    (_run(force_rms_error=1.6), "force RMS error 1.60 N (<= 1.5)"),
    (_run(force_max=21.0), "max |F| 21.0 N (<= 20)"),
    (_run(contact_fraction=0.95), "in contact 95.0 % (>= 98)"),
    (_run(lateral_error_max=0.0025), "sideways 2.50 mm (<= 2)"),
])
def test_each_bound_fails_the_demonstration_alone(run, says):
    verdict = judge_path(by_name(["curved_surface"])[0].path, run)
    assert not verdict.passed and says in verdict.summary, verdict.summary


def test_without_a_truth_the_angle_is_the_one_the_force_reads():
    run = _run(truth=False, normal_angle_rms=3.5)
    assert len(true_angles(run)) == 0
    verdict = judge_path(by_name(["curved_surface"])[0].path, run)
    assert not verdict.passed and "tool to normal read by force RMS 3.50 deg" in verdict.summary


def test_curved_surface_is_the_eighth_demonstration_with_its_own_scene():
    assert [s.name for s in SCENARIOS][-1] == "curved_surface" and len(SCENARIOS) == 8
    scene = dict(by_name(["curved_surface"])[0].scene)
    assert scene == {"fixture": "cylinder", "tool": "ball", "surface_seed": scene["surface_seed"]}
    assert int(scene["surface_seed"]) >= 0


def test_the_paths_middle_comes_from_demos_yaml_and_is_checked():
    geometry = DemoGeometry.from_dict({"curved_surface": {"middle": -0.15, "length": 0.25}})
    demo = by_name(["curved_surface"], geometry)[0].path
    assert demo.middle == -0.15 and demo.length == 0.25
    assert geometry.as_dict()["curved_surface"] == {"middle": -0.15, "length": 0.25}
    assert "curved_surface" not in DemoGeometry().as_dict()  # centred on the top unless said
    with pytest.raises(DemoConfigError, match=r"curved_surface\.middle: expected an angle within 1 rad"):
        DemoGeometry.from_dict({"curved_surface": {"middle": 2.0}})
    planned = cylinder_path(TOP, 0.25, 0.3, np.diag([1.0, -1.0, -1.0]), middle=-0.15)
    assert len(planned) == 31 and planned[15][0] == pytest.approx(TOP[0] - 0.25 * math.sin(0.15))
    assert curved_surface(-0.15).path.middle == -0.15


def test_the_plot_shows_the_path_from_the_side_and_the_force_and_angle_along_it(tmp_path):
    from thesis_demos.plotting import plot_path

    scenario = by_name(["curved_surface"])[0]
    run = _run()
    run.progress, run.force, run.angle = np.linspace(0, 1, 50), np.full(50, 10.0), np.zeros(50)
    run.feedback_t = np.linspace(0, 15, 50)
    run.planned = np.array([row[:3] for row in cylinder_path(TOP, 0.25, 0.3, np.diag([1.0, -1.0, -1.0]))])
    out = tmp_path / "curved_surface.png"
    plot_path(scenario, run, judge_path(scenario.path, run), str(out))
    assert out.stat().st_size > 10_000
