"""The demonstrations send the thesis parameters through the original service's fields."""

import pytest

law_requests = pytest.importorskip("thesis_demos.law_requests",
                                   reason="needs the built messages (make build)")


def test_hybrid_request_maps_each_axis_to_its_fields():
    from thesis_demos.scenarios import by_name

    req = law_requests.build_request(by_name(["hybrid"])[0])
    p = req.cart_impedance_params
    assert (req.direction_control_laws.x.type, req.direction_control_laws.z.type) == (3, 2)
    assert req.direction_control_laws.y.type == 0
    assert p.max_cart_vel.set.linear.x == -0.05
    assert p.max_path_deviation.translation.x == 0.30
    assert p.max_ctrl_force.set.force.x == 0.5
    assert (p.damping.translational.z, p.stiffness.translational.z) == (30.0, 100.0)
    assert p.max_ctrl_force.set.force.z == 0.0, "no force limit on the spring axis"


def test_compliant_move_asks_to_move_away_and_the_others_to_stop():
    from thesis_demos.scenarios import by_name

    action = law_requests.build_request(by_name(["compliant_move_z"])[0]).cart_impedance_params.max_ctrl_force
    assert (action.exceeded_action.move_away, action.exceeded_action.stop) == (True, False)
    action = law_requests.build_request(by_name(["hybrid"])[0]).cart_impedance_params.max_ctrl_force
    assert (action.exceeded_action.move_away, action.exceeded_action.stop) == (False, True)


def test_surface_following_presses_through_configure_laws_then_adds_the_x_move():
    from contact_control.request import RequestLimits, validate_laws_request
    from thesis_demos.scenarios import SURFACE_TARGET_FORCE, by_name

    scenario = by_name(["surface_following"])[0]
    assert scenario.uses_laws_service and not by_name(["hybrid"])[0].uses_laws_service
    first = law_requests.build_laws_request(scenario.laws, scenario.exceeded_action)
    assert (first.z.law, first.z.target_force, first.z.exceeded_action) == (4, SURFACE_TARGET_FORCE, 1)
    assert first.x.law == 0
    then = law_requests.build_laws_request(scenario.follow_up.laws, scenario.exceeded_action)
    assert then.z == first.z  # the same press: contact_control keeps it going bumplessly
    assert (then.x.law, then.x.velocity, then.x.exceeded_action) == (3, -0.01, 0)  # no force limit: stop
    # contact_control takes both as they are (a target of +10 N presses down on the block).
    limits = RequestLimits(max_velocity=0.25, max_force=25.0, default_velocity=0.01)
    z = validate_laws_request(then, limits)[2]
    assert z.target == SURFACE_TARGET_FORCE and z.velocity > 0.0
