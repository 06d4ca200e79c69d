"""The status readout texts, and that their code tables still match the message constants."""

from cartesian_impedance_msgs.msg import ControlLaw
from compliant_control_msgs.msg import AxisState, ContactControlStatus
from manipulator_control_gui.readout import (
    END_TEXT,
    LAW_TEXT,
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


def test_refusal_reason_is_read_from_the_status_message():
    message = (
        "move ended: z force limit; last request refused (code -4): axis x (compliant_move): desired velocity"
    )
    assert refusal_in_status(message) == (-4, "axis x (compliant_move): desired velocity")
    assert refusal_in_status("last request refused (code 99999): safety latched (over limit)") == (
        99999,
        "safety latched (over limit)",
    )
    assert refusal_in_status("move ended: z force limit") is None
    assert refusal_in_status("") is None
