"""The demonstrations send the thesis parameters through the original service's fields."""

import pytest

runner = pytest.importorskip("thesis_demos.runner", reason="needs the built messages (make build)")


def test_hybrid_request_maps_each_axis_to_its_fields():
    from thesis_demos.scenarios import by_name

    req = runner.build_request(by_name(["hybrid"])[0])
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

    action = runner.build_request(by_name(["compliant_move_z"])[0]).cart_impedance_params.max_ctrl_force
    assert (action.exceeded_action.move_away, action.exceeded_action.stop) == (True, False)
    action = runner.build_request(by_name(["hybrid"])[0]).cart_impedance_params.max_ctrl_force
    assert (action.exceeded_action.move_away, action.exceeded_action.stop) == (False, True)
