"""The status readout texts, and that their code tables still match the message constants."""

from cartesian_impedance_msgs.msg import ControlLaw
from compliant_control_msgs.msg import AxisState, ContactControlStatus
from manipulator_control_gui.readout import (
    END_TEXT,
    LAW_TEXT,
    REACTION_TEXT,
    SAFETY_TEXT,
    readout_from_status,
    refusal_in_status,
)


def test_code_tables_match_the_messages():
    ends = {
        AxisState.NONE,
        AxisState.FT_VIOLATION,
        AxisState.MAX_TRAVEL,
        AxisState.DIFF_VIOLATION,
        AxisState.NO_FT_DATA,
        AxisState.EXTERNAL_STOP,
    }
    assert set(END_TEXT) == ends
    assert "force/torque limit" in END_TEXT[AxisState.FT_VIOLATION]
    assert "max path deviation" in END_TEXT[AxisState.MAX_TRAVEL]
    assert "stopped" in END_TEXT[AxisState.EXTERNAL_STOP]
    safety = {
        ContactControlStatus.SAFETY_OK,
        ContactControlStatus.SAFETY_NAN,
        ContactControlStatus.SAFETY_OVER_LIMIT,
        ContactControlStatus.SAFETY_STALE,
        ContactControlStatus.SAFETY_NO_TF,
        ContactControlStatus.SAFETY_ZEROING,
    }
    assert set(SAFETY_TEXT) == safety
    assert "Reset" in SAFETY_TEXT[ContactControlStatus.SAFETY_OVER_LIMIT]
    assert LAW_TEXT[ControlLaw.TYPE_FOLLOWER] == "follower" and LAW_TEXT[ControlLaw.TYPE_SPRING] == "spring"
    assert LAW_TEXT[ControlLaw.TYPE_COMPLIANT_MOVE] == "compliant move"


def make_status() -> ContactControlStatus:
    status = ContactControlStatus(
        move_active=False, safety=ContactControlStatus.SAFETY_OK, message="z: force limit"
    )
    status.wrench.force.x, status.wrench.force.z, status.wrench.torque.y = 1.5, -0.62, 0.25
    status.velocity.linear.x, status.velocity.angular.z = 0.02, -0.05
    for axis in ("x", "y", "z", "rx", "ry", "rz"):
        status.axes.append(AxisState(axis=axis))
    status.axes[2].law = ControlLaw.TYPE_COMPLIANT_MOVE
    status.axes[2].end_condition = AxisState.FT_VIOLATION
    status.axes[2].force, status.axes[2].velocity, status.axes[2].travel = -0.62, 0.0, -0.081
    status.axes[5].force = 0.3
    return status


def test_readout_shows_wrench_velocity_and_end_conditions_with_units():
    readout = readout_from_status(make_status())
    assert readout.wrench == "F [+1.50 +0.00 -0.62] N   T [+0.00 +0.25 +0.00] N·m"
    assert readout.velocity.startswith("v [+0.020 +0.000 +0.000] m/s")
    assert "-0.050] rad/s" in readout.velocity
    assert readout.state == "no move · safety ok · z: force limit"
    assert readout.ok
    z = readout.axes["z"]
    assert (z.force, z.travel, z.end) == ("-0.62 N", "-0.081 m", "ended: force/torque limit")
    assert readout.axes["rz"].force == "+0.30 N·m" and readout.axes["x"].end == ""


def test_safety_stop_reads_as_not_ok():
    status = make_status()
    status.safety = ContactControlStatus.SAFETY_OVER_LIMIT
    status.move_active = True
    status.axes[2].end_condition = AxisState.NONE
    readout = readout_from_status(status)
    assert not readout.ok
    assert readout.axes["z"].end == "running"  # a law is set and the move runs
    assert readout.axes["y"].end == ""  # no law
    assert readout.state.startswith("move running · safety force over the global limit")


def test_exceeded_action_after_the_move_is_shown_on_its_axis():
    status = make_status()
    status.reacting = True
    status.axes[2].exceeded_action, status.axes[2].reacting = "move_away", True
    readout = readout_from_status(status)
    assert readout.state.startswith("move ended, exceeded action running · safety ok")
    assert readout.axes["z"].end == "ended: force/torque limit · moving away from the contact"
    status.axes[2].exceeded_action = "gravity_compensation"
    assert readout_from_status(status).axes["z"].end.endswith("hand-guiding (gravity compensation)")
    assert set(REACTION_TEXT) == {"move_away", "gravity_compensation"}
    status.reacting = status.axes[2].reacting = False  # done: back to the plain end condition
    readout = readout_from_status(status)
    assert readout.axes["z"].end == "ended: force/torque limit" and readout.state.startswith("no move")


def test_codes_this_panel_does_not_know_read_as_the_names_the_node_sends():
    status = make_status()
    status.safety, status.safety_name = 9, "new safety state"
    status.axes[2].end_condition, status.axes[2].end_condition_name = 8, "new end condition"
    readout = readout_from_status(status)
    assert "safety new safety state" in readout.state and readout.axes["z"].end == "ended: new end condition"


def test_refusal_reason_is_read_from_the_status_message():
    message = (
        "move ended: z force limit; last request refused (code -4): axis x (compliant_move): desired velocity"
    )
    assert refusal_in_status(message) == (-4, "axis x (compliant_move): desired velocity")
    assert refusal_in_status("last request refused (code 99999): safety latched (over limit)") == (
        99999,
        "safety latched (over limit)",
    )
    reason = "axis rx (follower): damping b > 0; RX reads cart_impedance_params.damping.rotational.x; got 0.0"
    message = f"move ended: z: max travel; last request refused (code -4): {reason}"
    assert refusal_in_status(message) == (-4, reason)  # the reason's own "; " do not cut it short
    assert refusal_in_status("move ended: z force limit") is None
    assert refusal_in_status("") is None
