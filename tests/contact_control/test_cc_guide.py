"""Hand-guiding (ContactStage.guide): followers with the guide damping and speed caps, refusals that change
nothing, and off leaves the arm at rest."""

from __future__ import annotations

import pytest
from contact_control.axes import LAW_FOLLOWER, LAW_NONE
from contact_control.laws import AxisLaw, law_velocity
from contact_control.params import AxisTuning
from contact_control.request import FAILURE, SUCCESS, empty_laws_request, validate_laws_request
from contact_control.stage import ContactStage

from contact_control import load_settings

from .cc_sim import DT

IDENTITY = [[1.0, 0, 0, 0], [0, 1.0, 0, 0], [0, 0, 1.0, 0], [0, 0, 0, 1.0]]


def stage(**params: object) -> ContactStage:
    settings = load_settings({"tare_on_startup": False, "lp_filter_enabled": False, **params})
    return ContactStage(settings, lambda frame: [row[:] for row in IDENTITY])


def run(st: ContactStage, wrench, seconds: float, t0: float) -> tuple[float, tuple | None]:
    t, v = t0, None
    for _ in range(round(seconds / DT)):
        t += DT
        out = st.on_wrench(wrench, "", None, t)
        v = out if out is not None else v
    return t, v


def test_guide_follows_a_push_at_most_at_its_speed_cap_and_off_brings_the_arm_to_rest():
    st = stage(guide_damping_linear=40.0, guide_max_velocity_linear=0.2)
    t, _ = run(st, (0.0,) * 6, 0.1, 0.0)
    answer, zero = st.guide(True, [], t)
    assert answer.ok and answer.code == SUCCESS and zero is None, answer.message
    assert "hand-guiding on" in answer.message and "x y z rx ry rz" in answer.message
    assert st.guiding and all(law.law == LAW_FOLLOWER for law in st.ctrl.laws)
    t, v = run(st, (6.0, 0, 0, 0, 0, 0), 0.5, t)  # 6 N along X: 6 / 40 = 0.15 m/s
    assert v is not None and v[0] == pytest.approx(0.15, abs=1e-6) and not any(v[1:])
    t, v = run(st, (0, -20.0, 0, 0, 0, 0), 0.5, t)  # 20 N along -Y would be 0.5 m/s: capped at 0.2
    assert v is not None and v[1] == pytest.approx(-0.2) and v[0] == 0.0
    answer, zero = st.guide(False, [], t)
    assert answer.ok and "off" in answer.message and zero == (0.0,) * 6
    assert not st.guiding and not st.ctrl.move_active
    t, v = run(st, (0, -20.0, 0, 0, 0, 0), 0.1, t)  # pushed after: nothing moves
    assert v is None or not any(v)
    answer, zero = st.guide(False, [], t)
    assert answer.ok and "was not on" in answer.message and zero is None


def test_guide_on_chosen_axes_only_and_unknown_axes_are_refused():
    st = stage()
    answer, _ = st.guide(True, ["x", "Z"], 0.0)
    assert answer.ok, answer.message
    assert [law.law for law in st.ctrl.laws] == [LAW_FOLLOWER, LAW_NONE, LAW_FOLLOWER, 0, 0, 0]
    move = st.ctrl.move_id
    answer, _ = st.guide(True, ["x", "w"], 0.1)
    assert not answer.ok and "unknown axis w" in answer.message
    assert st.ctrl.move_id == move and st.guiding  # unchanged


def test_guide_is_refused_while_a_contact_move_runs_with_the_reason_and_the_move_goes_on():
    st = stage()
    req = empty_laws_request()
    req.z.law, req.z.damping, req.z.target_force, req.z.velocity = 4, 2000.0, 10.0, 0.01
    assert st.configure(req, 0.0, per_axis=True).ok
    move = st.ctrl.move_id
    answer, zero = st.guide(True, [], 0.1)
    assert not answer.ok and answer.code == FAILURE and zero is None
    assert "contact move is running" in answer.message and "force_tracking" in answer.message
    assert st.ctrl.move_id == move and st.ctrl.move_active and not st.guiding
    answer, zero = st.guide(False, [], 0.2)  # off does not stop somebody else's move
    assert answer.ok and zero is None and st.ctrl.move_active


def test_guide_is_refused_while_the_safety_is_latched():
    st = stage(force_limit_samples=1)
    t, _ = run(st, (0, 0, 40.0, 0, 0, 0), 0.01, 0.0)
    answer, _ = st.guide(True, [], t)
    assert not answer.ok and "safety latched" in answer.message and not st.guiding


def test_a_follower_speed_cap_comes_from_configure_laws_only():
    tuning = AxisTuning()
    capped = AxisLaw(LAW_FOLLOWER, damping=10.0, velocity=0.1)
    assert law_velocity(capped, tuning, 5.0, 0.0) == pytest.approx(0.1)
    assert law_velocity(capped, tuning, -5.0, 0.0) == pytest.approx(-0.1)
    assert law_velocity(AxisLaw(LAW_FOLLOWER, damping=10.0), tuning, 5.0, 0.0) == pytest.approx(0.5)
    req = empty_laws_request()
    req.x.law, req.x.damping, req.x.velocity = 1, 30.0, 0.05
    assert validate_laws_request(req)[0].velocity == 0.05
    req.x.velocity = -0.05
    with pytest.raises(Exception, match="speed cap"):
        validate_laws_request(req)


def test_a_push_on_the_tool_far_below_the_base_frame_does_not_turn_the_guided_tool():
    """The torque is taken about the end effector, not the control frame's origin: TIAGo's tool works 0.6 m
    below its torso frame, and about that origin a 6 N push read 3.6 Nm, over the 2.5 Nm rotational
    deadband, so hand-guiding turned the tool while it was pushed along a line."""
    sensor = [[1.0, 0, 0, 0.5], [0, 1.0, 0, 0.0], [0, 0, 1.0, -0.6], [0, 0, 0, 1.0]]
    eef = [[1.0, 0, 0, 0.5], [0, 1.0, 0, 0.0], [0, 0, 1.0, -0.72], [0, 0, 0, 1.0]]  # tool tip, 0.12 m lower
    poses = {"ft_sensor": sensor, "tool_tip": eef}
    settings = load_settings({"tare_on_startup": False, "lp_filter_enabled": False, "fixed_frame": "base",
                              "control_frame": "base", "velocity_command_frame": "base",
                              "ft_sensor_frame": "ft_sensor", "eef_frame": "tool_tip"})
    st = ContactStage(settings, lambda frame: [row[:] for row in poses.get(frame, IDENTITY)])
    t, _ = run(st, (0.0,) * 6, 0.1, 0.0)
    assert st.guide(True, [], t)[0].ok
    t, v = run(st, (6.0, 0, 0, 0, 0, 0), 0.5, t)  # 6 N along X at the sensor: 0.72 Nm about the tool tip
    assert v is not None and v[0] > 0.1 and v[3:] == (0.0, 0.0, 0.0), v
    t, v = run(st, (0.0, 0, 0, 0, 3.0, 0), 0.5, t)  # a twist of the hand over the deadband turns it
    assert v is not None and v[4] > 0.0, v
