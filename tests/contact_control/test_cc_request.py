"""Service request -> per-axis laws: the SPEC mapping (without the original's bugs) and the refusals."""

import math

import pytest
from contact_control.axes import (
    AXES,
    EXCEEDED_GRAVITY_COMPENSATION,
    EXCEEDED_MOVE_AWAY,
    EXCEEDED_STOP,
    LAW_COMPLIANT_MOVE,
    LAW_FOLLOWER,
    LAW_NONE,
    LAW_SPRING,
)
from contact_control.laws import AxisLaw
from contact_control.request import (
    FAILURE,
    SET_CARTESIAN_CONTROL_FAILED,
    SET_CONTROL_FORCE_FAILED,
    SET_DOF_FAILED,
    SET_FORCE_STIFFNESS_FAILED,
    RequestError,
    RequestLimits,
    empty_laws_request,
    empty_request,
    fill_laws_request,
    fill_request,
    validate_laws_request,
    validate_request,
)


def distinct_request(law_type: int):
    """Every axis gets `law_type` and every field a value unique to (field, axis), so mix-ups show."""
    req = empty_request()
    p = req.cart_impedance_params
    for i, c in enumerate("xyz"):
        setattr(p.damping.translational, c, 10.0 + i)
        setattr(p.damping.rotational, c, 20.0 + i)
        setattr(p.stiffness.translational, c, 30.0 + i)
        setattr(p.stiffness.rotational, c, 40.0 + i)
        setattr(p.max_cart_vel.set.linear, c, 0.01 * (1 + i))
        setattr(p.max_cart_vel.set.angular, c, 0.1 * (1 + i))
        setattr(p.max_ctrl_force.set.force, c, 1.0 + i)
        setattr(p.max_ctrl_force.set.torque, c, 4.0 + i)
        setattr(p.max_path_deviation.translation, c, 0.1 * (1 + i))
        setattr(p.max_path_deviation.rotation, c, 0.5 * (1 + i))
    for name in AXES:
        getattr(req.direction_control_laws, name).type = law_type
    return req


def test_each_axis_reads_its_own_fields():
    springs = validate_request(distinct_request(LAW_SPRING))
    moves = validate_request(distinct_request(LAW_COMPLIANT_MOVE))
    for i in range(3):
        assert springs[i] == AxisLaw(
            LAW_SPRING,
            damping=10.0 + i,
            stiffness=30.0 + i,
            force_limit=1.0 + i,
            max_travel=pytest.approx(0.1 * (1 + i)),
        )
        # RX, RY, RZ read damping.rotational / torque / rotation / angular (the original mapped RY, RZ to
        # RX and read linear velocity and force fields for rotations).
        assert springs[3 + i] == AxisLaw(
            LAW_SPRING, damping=20.0 + i, stiffness=40.0 + i, force_limit=4.0 + i, max_travel=0.5 * (1 + i)
        )
        assert moves[i].velocity == pytest.approx(0.01 * (1 + i))
        assert moves[3 + i].velocity == pytest.approx(0.1 * (1 + i))


def test_unknown_type_disables_the_axis_and_follower_ignores_stiffness():
    req = distinct_request(LAW_FOLLOWER)
    req.direction_control_laws.ry.type = LAW_NONE
    laws = validate_request(req)
    assert laws[4] == AxisLaw()
    assert laws[0] == AxisLaw(LAW_FOLLOWER, damping=10.0, force_limit=1.0, max_travel=pytest.approx(0.1))


def test_thesis_demos_are_accepted():
    # Follower on Z, b = 30.
    req = empty_request()
    req.direction_control_laws.z.type = LAW_FOLLOWER
    req.cart_impedance_params.damping.translational.z = 30.0
    assert validate_request(req)[2] == AxisLaw(LAW_FOLLOWER, damping=30.0)
    # Compliant move on Z with max force 0.5 N, no max path deviation ("-" in the thesis).
    req = empty_request()
    req.direction_control_laws.z.type = LAW_COMPLIANT_MOVE
    req.cart_impedance_params.max_cart_vel.set.linear.z = -0.05
    req.cart_impedance_params.max_ctrl_force.set.force.z = 0.5
    req.cart_impedance_params.max_ctrl_force.set.torque.z = 0.5
    assert validate_request(req)[2] == AxisLaw(LAW_COMPLIANT_MOVE, velocity=-0.05, force_limit=0.5)


def test_fill_request_round_trips():
    laws = [
        AxisLaw(LAW_FOLLOWER, damping=30.0),
        AxisLaw(),
        AxisLaw(LAW_SPRING, damping=30.0, stiffness=100.0),
        AxisLaw(LAW_COMPLIANT_MOVE, damping=5.0, velocity=0.1, force_limit=1.0, max_travel=0.5),
        AxisLaw(),
        AxisLaw(LAW_FOLLOWER, damping=2.0, force_limit=3.0),
    ]
    assert validate_request(fill_request(empty_request(), laws)) == laws


def _req(axis: str, law: int, **fields):
    """A request with one active axis; fields: b, k, v, limit, travel."""
    req = empty_request()
    getattr(req.direction_control_laws, axis).type = law
    p = req.cart_impedance_params
    lin = axis in ("x", "y", "z")
    c = axis[-1]
    groups = {
        "b": p.damping.translational if lin else p.damping.rotational,
        "k": p.stiffness.translational if lin else p.stiffness.rotational,
        "v": p.max_cart_vel.set.linear if lin else p.max_cart_vel.set.angular,
        "limit": p.max_ctrl_force.set.force if lin else p.max_ctrl_force.set.torque,
        "travel": p.max_path_deviation.translation if lin else p.max_path_deviation.rotation,
    }
    for key, value in fields.items():
        setattr(groups[key], c, value)
    return req


NAN = math.nan
REFUSED = [  # (request, code, words in the message)
    (_req("x", LAW_SPRING, b=30, k=0), SET_FORCE_STIFFNESS_FAILED, "axis x (spring): stiffness"),
    (_req("rz", LAW_SPRING, b=30, k=-1), SET_FORCE_STIFFNESS_FAILED, "axis rz"),
    (_req("y", LAW_SPRING, b=0, k=100), SET_CARTESIAN_CONTROL_FAILED, "damping"),
    (_req("z", LAW_FOLLOWER, b=0), SET_CARTESIAN_CONTROL_FAILED, "axis z (follower): damping"),
    (_req("ry", LAW_FOLLOWER, b=-30), SET_CARTESIAN_CONTROL_FAILED, "axis ry"),
    (_req("z", LAW_FOLLOWER, b=NAN), SET_CARTESIAN_CONTROL_FAILED, "damping"),
    (_req("x", LAW_COMPLIANT_MOVE, v=0, travel=0.3), SET_CARTESIAN_CONTROL_FAILED, "desired velocity"),
    (_req("x", LAW_COMPLIANT_MOVE, v=0.1, travel=-0.3), SET_CARTESIAN_CONTROL_FAILED, "max path deviation"),
    (_req("x", LAW_COMPLIANT_MOVE, v=0.1), SET_CARTESIAN_CONTROL_FAILED, "max path deviation > 0 or a force"),
    (_req("x", LAW_COMPLIANT_MOVE, v=NAN, travel=0.3), SET_CARTESIAN_CONTROL_FAILED, "desired velocity"),
    (_req("x", LAW_COMPLIANT_MOVE, v=0.1, b=-1, travel=0.3), SET_CARTESIAN_CONTROL_FAILED, "damping"),
    (_req("x", LAW_FOLLOWER, b=30, limit=-1), SET_CONTROL_FORCE_FAILED, "limit"),
    (_req("rx", LAW_FOLLOWER, b=30, limit=NAN), SET_CONTROL_FORCE_FAILED, "limit"),
    (_req("y", LAW_FOLLOWER, b=30, travel=NAN), SET_CARTESIAN_CONTROL_FAILED, "max path deviation"),
    (_req("y", LAW_SPRING, b=30, k=100, travel=math.inf), SET_CARTESIAN_CONTROL_FAILED, "max path deviation"),
    (_req("z", 7, b=30), SET_DOF_FAILED, "unknown law type 7"),
]


@pytest.mark.parametrize(("req", "code", "words"), REFUSED)
def test_inconsistent_requests_are_refused(req, code, words):
    with pytest.raises(RequestError) as err:
        validate_request(req)
    assert err.value.code == code
    assert words in err.value.message


def test_limits_bound_velocity_and_force_ranges():
    limits = RequestLimits(max_velocity=0.25, max_angular_velocity=0.5, max_force=25.0, max_torque=10.0)
    assert validate_request(_req("x", LAW_COMPLIANT_MOVE, v=0.25, travel=0.3), limits)[0].velocity == 0.25
    with pytest.raises(RequestError) as err:
        validate_request(_req("x", LAW_COMPLIANT_MOVE, v=-0.3, travel=0.3), limits)
    assert err.value.code == SET_CARTESIAN_CONTROL_FAILED
    with pytest.raises(RequestError) as err:
        validate_request(_req("rx", LAW_FOLLOWER, b=1, limit=12.0), limits)
    assert err.value.code == SET_CONTROL_FORCE_FAILED


def test_a_compliant_move_no_faster_than_the_min_velocity_is_refused():
    """contact_control zeroes commands of at most min_velocity: such a move would never start."""
    limits = RequestLimits(min_velocity=0.005, min_angular_velocity=0.005)
    assert validate_request(_req("z", LAW_COMPLIANT_MOVE, v=-0.006, travel=0.1), limits)[2].velocity == -0.006
    with pytest.raises(RequestError) as err:
        validate_request(_req("z", LAW_COMPLIANT_MOVE, v=-0.005, travel=0.1), limits)
    assert err.value.code == SET_CARTESIAN_CONTROL_FAILED
    assert "desired velocity 0.005 is not above min_velocity_linear 0.005 m/s" in err.value.message
    with pytest.raises(RequestError, match="min_velocity_angular"):
        validate_request(_req("rz", LAW_COMPLIANT_MOVE, v=0.004, travel=0.1), limits)


def test_malformed_objects_are_refused():
    with pytest.raises(RequestError) as err:
        validate_request(object())
    assert err.value.code == FAILURE
    with pytest.raises(RequestError) as err:
        validate_laws_request(object())
    assert err.value.code == FAILURE


@pytest.mark.parametrize(
    ("flag", "action"),
    [("move_away", EXCEEDED_MOVE_AWAY), ("gravity_compensation", EXCEEDED_GRAVITY_COMPENSATION)],
)
def test_the_one_exceeded_action_applies_to_the_axes_with_a_force_limit(flag, action):
    req = _req("z", LAW_COMPLIANT_MOVE, b=30, v=-0.01, limit=0.5)
    req.direction_control_laws.x.type = LAW_FOLLOWER
    req.cart_impedance_params.damping.translational.x = 30.0  # no force limit on X: nothing to exceed
    setattr(req.cart_impedance_params.max_ctrl_force.exceeded_action, flag, True)
    laws = validate_request(req)
    assert laws[2].exceeded_action == action and laws[2].force_limit == 0.5
    assert laws[0].exceeded_action == EXCEEDED_STOP
    assert validate_request(fill_request(empty_request(), laws)) == laws  # the flag round-trips


def test_exceeded_action_refusals_name_the_field():
    req = _req("z", LAW_COMPLIANT_MOVE, b=30, v=-0.01, limit=0.5)
    action = req.cart_impedance_params.max_ctrl_force.exceeded_action
    action.stop = action.move_away = True
    with pytest.raises(RequestError) as err:
        validate_request(req)
    assert err.value.code == SET_CONTROL_FORCE_FAILED
    assert "cart_impedance_params.max_ctrl_force.exceeded_action" in err.value.message
    assert "stop, move_away" in err.value.message
    # Gravity compensation turns the axis into a follower: a compliant move without force term cannot.
    req = _req("z", LAW_COMPLIANT_MOVE, v=-0.01, limit=0.5)
    req.cart_impedance_params.max_ctrl_force.exceeded_action.gravity_compensation = True
    with pytest.raises(RequestError) as err:
        validate_request(req)
    assert "Z reads cart_impedance_params.damping.translational.z; got 0.0" in err.value.message


def test_refusals_name_the_field_a_user_must_set():
    # RX with only the linear fields filled in: the message says where RX reads its damping.
    req = _req("rx", LAW_FOLLOWER)
    req.cart_impedance_params.damping.translational.x = 30.0
    with pytest.raises(RequestError) as err:
        validate_request(req)
    assert err.value.message.endswith("RX reads cart_impedance_params.damping.rotational.x; got 0.0")
    with pytest.raises(RequestError) as err:
        validate_request(_req("y", LAW_SPRING, b=30))
    assert "Y reads cart_impedance_params.stiffness.translational.y; got 0.0" in err.value.message


NODE_LIMITS = RequestLimits(0.25, 0.25, 25.0, 25.0, default_velocity=0.01, default_angular_velocity=0.05)


@pytest.mark.parametrize(("limit", "velocity"), [(-0.5, -0.01), (0.5, 0.01)])
def test_compliant_move_typed_as_the_thesis_gives_it_approaches_at_the_default_velocity(limit, velocity):
    # "Compliant move on Z, max force 0.5 N" with b = 30 and no desired velocity: the limit's sign says where.
    req = _req("z", LAW_COMPLIANT_MOVE, b=30, limit=limit)
    assert validate_request(req, NODE_LIMITS)[2] == AxisLaw(
        LAW_COMPLIANT_MOVE, damping=30.0, velocity=velocity, force_limit=0.5
    )
    assert validate_request(_req("rz", LAW_COMPLIANT_MOVE, limit=-2.0), NODE_LIMITS)[5].velocity == -0.05


def test_compliant_move_without_velocity_or_signed_limit_names_the_field_to_add():
    with pytest.raises(RequestError) as err:
        validate_request(_req("z", LAW_COMPLIANT_MOVE, b=30, travel=0.1), NODE_LIMITS)
    assert err.value.code == SET_CARTESIAN_CONTROL_FAILED
    assert "Z reads cart_impedance_params.max_cart_vel.set.linear.z; got 0.0" in err.value.message
    assert "cart_impedance_params.max_ctrl_force.set.force.z" in err.value.message
    with pytest.raises(RequestError):  # no default configured (the library alone): velocity required
        validate_request(_req("z", LAW_COMPLIANT_MOVE, b=30, limit=0.5))
    with pytest.raises(RequestError) as err:  # a negative limit is a direction only for such a move
        validate_request(_req("z", LAW_FOLLOWER, b=30, limit=-0.5), NODE_LIMITS)
    assert "Z reads cart_impedance_params.max_ctrl_force.set.force.z; got -0.5" in err.value.message


def _laws_req(axis: str, **fields):
    req = empty_laws_request()
    for key, value in fields.items():
        setattr(getattr(req, axis), key, value)
    return req


def test_configure_laws_request_sets_each_axis_with_its_own_action():
    laws = [
        AxisLaw(LAW_COMPLIANT_MOVE, damping=30.0, velocity=-0.01, force_limit=0.5, exceeded_action=1),
        AxisLaw(),
        AxisLaw(LAW_SPRING, damping=30.0, stiffness=100.0),
        AxisLaw(LAW_FOLLOWER, damping=2.0, force_limit=3.0, exceeded_action=2),
        AxisLaw(),
        AxisLaw(LAW_FOLLOWER, damping=2.0, force_limit=3.0),
    ]
    assert validate_laws_request(fill_laws_request(empty_laws_request(), laws)) == laws
    with pytest.raises(ValueError, match="ConfigureLaws"):  # the original message has one action for all
        fill_request(empty_request(), laws)


LAWS_REFUSED = [  # (request, code, words)
    (_laws_req("z", law=LAW_FOLLOWER), SET_CARTESIAN_CONTROL_FAILED, "Z reads z.damping; got 0.0"),
    (_laws_req("z", law=9), SET_DOF_FAILED, "Z reads z.law; got 9"),
    (_laws_req("x", law=LAW_FOLLOWER, damping=30.0, force_limit=1.0, exceeded_action=7),
     SET_CONTROL_FORCE_FAILED, "X reads x.exceeded_action; got 7"),
    (_laws_req("x", law=LAW_FOLLOWER, damping=30.0, exceeded_action=1),
     SET_CONTROL_FORCE_FAILED, "set x.force_limit > 0"),
    (_laws_req("ry", law=LAW_COMPLIANT_MOVE, max_travel=0.2), SET_CARTESIAN_CONTROL_FAILED,
     "RY reads ry.velocity"),
]


@pytest.mark.parametrize(("req", "code", "words"), LAWS_REFUSED)
def test_configure_laws_refusals_name_the_field(req, code, words):
    with pytest.raises(RequestError) as err:
        validate_laws_request(req, NODE_LIMITS)
    assert err.value.code == code
    assert words in err.value.message


def test_works_with_the_generated_message():
    srv = pytest.importorskip("cartesian_impedance_msgs.srv", reason="needs devel/setup.bash")
    req = srv.ConfigureForceControlRequest()
    laws = [
        AxisLaw(),
        AxisLaw(),
        AxisLaw(LAW_FOLLOWER, damping=30.0),
        AxisLaw(),
        AxisLaw(),
        AxisLaw(LAW_SPRING, damping=3.0, stiffness=10.0),
    ]
    assert validate_request(fill_request(req, laws)) == laws
    laws_srv = pytest.importorskip("compliant_control_msgs.srv")
    laws[2] = AxisLaw(LAW_FOLLOWER, damping=30.0, force_limit=2.0, exceeded_action=EXCEEDED_MOVE_AWAY)
    request = fill_laws_request(laws_srv.ConfigureLawsRequest(), laws)
    assert validate_laws_request(request) == laws
