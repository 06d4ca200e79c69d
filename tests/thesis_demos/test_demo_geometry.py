"""The demonstrations take an arm's directions and distances from its package, and say beforehand what
the arm cannot do."""

import pathlib

import pytest
from thesis_demos.geometry import (
    DemoConfigError,
    DemoGeometry,
    Obstacle,
    load_geometry,
    load_obstacle,
    preflight,
    tool_radius,
)
from thesis_demos.scenarios import SCENARIOS, build_scenarios, by_name, fitted

SRC = pathlib.Path(__file__).resolve().parents[2] / "src"
ROBOT_PACKAGES = sorted(p for p in SRC.iterdir() if p.name.endswith("_custom"))


def test_defaults_are_the_thesis_sized_scenarios():
    hybrid = by_name(["hybrid"])[0]
    assert hybrid.laws["x"].max_travel == 0.30 and hybrid.laws["x"].velocity == -0.05
    assert by_name(["compliant_move_z"])[0].laws["z"].velocity == -0.01
    assert SCENARIOS == build_scenarios(DemoGeometry())


def test_a_smaller_arm_gets_shorter_motions_in_its_directions():
    g = DemoGeometry.from_dict({
        "hybrid": {"travel": 0.15, "direction": 1},
        "compliant_move": {"max_travel": 0.10},
        "spring": {"direction": -1},
        "follower": {"push_duration": 0.5},
    })
    hybrid, = by_name(["hybrid"], g)
    assert hybrid.laws["x"].max_travel == 0.15 and hybrid.laws["x"].velocity == 0.05
    assert by_name(["compliant_move_z"], g)[0].laws["z"].max_travel == 0.10
    assert by_name(["spring_x"], g)[0].pushes[0].force[0] == -15.0
    follower, = by_name(["follower_z"], g)
    assert follower.pushes[0].duration == 0.5 and follower.pushes[1].start > follower.pushes[0].end


@pytest.mark.parametrize(
    ("data", "named"),
    [
        ({"hybrid": {"travel": -0.1}}, "hybrid.travel"),
        ({"hybrid": {"direction": 0}}, "hybrid.direction"),
        ({"spring": {"push": 3}}, "spring: unknown keys ['push']"),
        ({"dance": {}}, "unknown sections ['dance']"),
        ({"follower": {"push_force": "five"}}, "follower.push_force"),
    ],
)
def test_bad_demos_yaml_names_the_key(data, named):
    with pytest.raises(DemoConfigError, match=named.replace("[", r"\[").replace("]", r"\]")):
        DemoGeometry.from_dict(data)


def test_geometry_round_trips_through_yaml_mapping():
    g = DemoGeometry(hybrid_travel=0.17, hybrid_direction=1, compliant_max_travel=0.11)
    assert DemoGeometry.from_dict(g.as_dict()) == g


BOX = Obstacle((0.6, 0.1, 0.065), (0.15, 0.15, 0.13))


def test_preflight_passes_the_thesis_setup():
    assert preflight(DemoGeometry(), (0.6, 0.1, 0.20), BOX, 0.03) == {}


def test_preflight_names_an_obstacle_beside_the_tool():
    problems = preflight(DemoGeometry(), (0.3, 0.1, 0.20), BOX, 0.03)
    assert "not under the tool tip" in problems["compliant_move_z"]


def test_preflight_names_an_obstacle_out_of_reach_of_the_move():
    problems = preflight(DemoGeometry(compliant_max_travel=0.05), (0.6, 0.1, 0.20), BOX, 0.03)
    assert "would end by its path deviation, not by contact" in problems["compliant_move_z"]


def test_preflight_names_a_tool_already_touching():
    problems = preflight(DemoGeometry(), (0.6, 0.1, 0.14), BOX, 0.03)
    assert "needs at least" in problems["compliant_move_z"]


def test_preflight_names_a_hybrid_path_through_the_obstacle():
    # Starting beside the box, low, and travelling toward it.
    problems = preflight(DemoGeometry(hybrid_direction=-1), (0.9, 0.1, 0.10), BOX, 0.03)
    assert "run into the obstacle" in problems["hybrid"]


def test_preflight_without_obstacle_refuses_only_the_demos_that_press_on_it():
    problems = preflight(DemoGeometry(), (0.6, 0.1, 0.20), None)
    assert sorted(problems) == ["compliant_move_z", "surface_following", "teach_and_replay"]


def test_surface_following_needs_a_block_the_tool_stays_on_over_its_slide():
    from thesis_demos.geometry import Obstacle

    wide = Obstacle(position=(0.6, 0.1, 0.065), size=(0.15, 0.15, 0.13))
    narrow = Obstacle(position=(0.6, 0.1, 0.065), size=(0.11, 0.11, 0.13))
    assert "surface_following" not in preflight(DemoGeometry(), (0.6, 0.1, 0.20), wide, tool_radius=0.03)
    reason = preflight(DemoGeometry(), (0.6, 0.1, 0.20), narrow, tool_radius=0.03)["surface_following"]
    assert "60 mm wide" in reason and "11 x 11 cm" in reason


@pytest.mark.parametrize("package", ROBOT_PACKAGES, ids=lambda p: p.name)
def test_every_robot_package_has_demos_its_start_pose_and_scene_allow(package):
    g = load_geometry(str(package / "config" / "demos.yaml"))
    obstacle = load_obstacle(str(package / "config" / "sim.yaml"))
    radius = tool_radius(str(package / "config" / "description.args"))
    assert obstacle is not None
    # The tip over the obstacle's centre at the package's stated gap is checked end to end; here the
    # obstacle must at least be reachable by the compliant move from above.
    assert obstacle.size[0] / 2 > radius and obstacle.size[1] / 2 > radius
    assert g.compliant_max_travel > 0.045


def floor(filtered_force: float, raw: float = 1.0):
    from contact_control.noise_floor import NoiseFloor

    return NoiseFloor((raw,) * 6, 0.0, 0, (filtered_force,) * 3 + (0.04,) * 3)


def test_the_contact_force_limit_is_per_driver_and_a_sensor_that_cannot_resolve_it_is_named():
    from thesis_demos.cli import unresolvable
    from thesis_demos.geometry import DemoConfigError, DemoGeometry
    from thesis_demos.scenarios import by_name

    g = DemoGeometry.from_dict({"contact_force": {"limit": 0.5, "drivers": {"franka_ros": 1.5}}})
    assert g.contact_force_limit == 0.5 and g.for_driver("ur_robot_driver") == g
    franka = g.for_driver("franka_ros")
    (move, hybrid) = by_name(["compliant_move_z", "hybrid"], franka)
    assert move.laws["z"].force_limit == 1.5 and hybrid.laws["x"].force_limit == 1.5
    assert "max force 1.5 N" in move.title
    assert DemoGeometry.from_dict(g.as_dict()) == g and "contact_force" not in DemoGeometry().as_dict()
    for bad in ({"limit": -1}, {"drivers": {"franka_ros": "x"}}, {"limits": 1}):
        with pytest.raises(DemoConfigError, match="contact_force"):
            DemoGeometry.from_dict({"contact_force": bad})
    # What run_demos prints as [CANNOT]: the noise floor resolves 0.62 N, the thesis's limit is 0.5 N.
    (thesis,) = by_name(["compliant_move_z"], g)
    reason = unresolvable(thesis, floor(0.124), 5.0)
    assert "resolves forces of 0.62 N" in reason and "stops at 0.5 N" in reason
    assert unresolvable(move, floor(0.124), 5.0) == "" and unresolvable(thesis, None, 5.0) == ""
    assert unresolvable(thesis, floor(0.124), 0.0) == ""  # noise_limit_sigmas 0: nothing checked
    # The offset moving with the pose counts too: 1.5 N passes on the noise alone, not with a 0.3 N
    # residual of a bias map (hypot(0.62, 5 x 0.3) = 1.6 N), and the reason says so.
    assert unresolvable(move, floor(0.124), 5.0, pose=(0.0, 0.0)) == ""
    reason = unresolvable(move, floor(0.124), 5.0, pose=(0.3, 0.0))
    assert "resolves forces of 1.6 N" in reason and "offset's change with the pose, 0.3 N" in reason
    # A current estimate (1.05 N after the filter, resolves 5.3 N): the follower's 5 N push is in its noise,
    # and force tracking's +-1.5 N is inside the +-2.1 N its input wanders; the e-series' 0.24 N is not.
    (follower, surface) = by_name(["follower_z", "surface_following"], g)
    assert "pushes with 5 N, within its noise" in unresolvable(follower, floor(1.05), 5.0)
    assert "wanders +-2.1 N" in unresolvable(surface, floor(1.05), 5.0)
    assert unresolvable(follower, floor(0.24), 5.0) == "" and unresolvable(surface, floor(0.24), 5.0) == ""
    # The spring's 15 N push plus 3 raw stds of a 4 N-noise estimate reaches the 25 N global limit.
    (spring,) = by_name(["spring_x"], g)
    assert "reaches contact_control's 25 N global limit" in unresolvable(spring, floor(1.05, raw=4.0), 5.0)
    assert unresolvable(spring, floor(1.05, raw=4.0), 5.0, global_force=40.0) == ""
    assert unresolvable(spring, floor(0.24, raw=0.63), 5.0) == ""


def test_the_taught_l_is_scaled_onto_the_block_and_a_block_too_small_is_named():
    from thesis_demos.geometry import RobotSetup, fit_l

    # The 15 cm block with a 6 cm wide tool: 15 - 2 x (3 + 0.5) = 8 cm for the 10 cm leg: an 8 x 4 cm L,
    # centred on the block, X toward the base (-X), Y toward y = 0 (here from y = 0.1: -Y).
    corner, legs = fit_l((0.6, 0.1, 0.20), BOX, 0.03)
    assert legs == pytest.approx((-0.08, -0.04)) and corner == pytest.approx((0.04, 0.02))
    start = (0.6 + corner[0], 0.1 + corner[1])
    for x, y in (start, (start[0] + legs[0], start[1]), (start[0] + legs[0], start[1] + legs[1])):
        assert BOX.covers(x, y, inset=0.03)  # every corner of the L keeps the whole tool on the block
    # A large block: the full 10 x 5 cm L, +Y from y = 0.
    big = Obstacle((0.5, 0.0, 0.05), (0.4, 0.4, 0.1))
    assert fit_l((0.5, 0.0, 0.2), big, 0.03) == ((pytest.approx(0.05), pytest.approx(-0.025)),
                                                  (pytest.approx(-0.10), pytest.approx(0.05)))
    small = Obstacle((0.6, 0.1, 0.065), (0.09, 0.09, 0.13))
    reason = preflight(DemoGeometry(), (0.6, 0.1, 0.20), small, 0.03)["teach_and_replay"]
    assert "leaves 2.0 cm for the L's 10 cm leg" in reason and "a larger block" in reason
    assert "not under the tool tip" in fit_l((0.3, 0.1, 0.2), BOX, 0.03)
    # run_demos' scenarios get the arm's L; without a scene, the thesis-sized one stays.
    scenarios = by_name(["teach_and_replay", "spring_x"])
    scaled = fitted(RobotSetup(DemoGeometry(), BOX, 0.03, checks_scene=True), scenarios, (0.6, 0.1, 0.2))
    assert scaled[0].teach.legs == pytest.approx((-0.08, -0.04)) and "8 x 4 cm" in scaled[0].title
    assert scaled[1] is scenarios[1]
    assert fitted(RobotSetup(DemoGeometry()), scenarios, (0.6, 0.1, 0.2)) == scenarios
