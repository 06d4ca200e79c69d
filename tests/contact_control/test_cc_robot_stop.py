"""The robot stopped by itself (jog_arm's ~robot_stop): contact_control's running move ends with the
reason, requests and hand-guiding are refused saying why, and taken again once the robot runs."""

from __future__ import annotations

import pytest
from contact_control.request import FAILURE, empty_laws_request
from contact_control.stage import ContactStage

from contact_control import load_settings

from .cc_sim import DT

pytestmark = pytest.mark.cobot_safety

IDENTITY = [[1.0, 0, 0, 0], [0, 1.0, 0, 0], [0, 0, 1.0, 0], [0, 0, 0, 1.0]]
REASON = "the robot stopped: ur_hardware_interface/safety_mode reads PROTECTIVE_STOP (3)"


def _pressing() -> tuple[ContactStage, float]:
    st = ContactStage(load_settings({"tare_on_startup": False, "lp_filter_enabled": False}),
                      lambda frame: [row[:] for row in IDENTITY])
    req = empty_laws_request()
    req.z.law, req.z.damping, req.z.target_force, req.z.velocity = 4, 2000.0, 10.0, 0.01
    assert st.configure(req, 0.0, per_axis=True).ok
    t = 0.0
    for _ in range(20):
        t += DT
        st.on_wrench((0.0,) * 6, "", None, t)
    assert st.ctrl.move_active
    return st, t


def test_a_robot_stop_ends_the_move_with_its_reason_and_refuses_requests_until_it_runs():
    st, t = _pressing()
    assert st.robot_stopped(REASON) == (0.0,) * 6  # one zero twist
    assert not st.ctrl.move_active and st.ended
    assert REASON in st.ctrl.end_message
    _result, message = st.status()
    assert REASON in message
    req = empty_laws_request()
    req.z.law, req.z.damping, req.z.target_force, req.z.velocity = 4, 2000.0, 10.0, 0.01
    answer = st.configure(req, t, per_axis=True)
    assert not answer.ok and answer.code == FAILURE and "PROTECTIVE_STOP" in answer.message
    assert "jog_arm_server/recover" in answer.message and not st.ctrl.move_active
    answer, zero = st.guide(True, [], t)
    assert not answer.ok and "PROTECTIVE_STOP" in answer.message and zero is None and not st.guiding
    st.robot_recovered()
    assert st.configure(req, t, per_axis=True).ok and st.ctrl.move_active
