"""ContactControl.contact_force: the compensated contact force for jog_arm's guard, without filter lag."""

import numpy as np
import pytest
from cc_sim import controller, rot


def test_contact_force_is_compensated_and_rotated_but_not_filtered():
    ctrl = controller(
        tool_mass=1.0, tool_com=[0.0, 0.0, 0.05], lp_filter_delta_t=0.002, lp_filter_cutoff_freq=5.0
    )
    R = rot([1.0, 0.0, 0.0], np.pi)  # sensor z down, as on the simulated arms
    T = np.eye(4)
    T[:3, :3] = R  # control frame = fixed frame
    weight = R.T @ np.array([0.0, 0.0, -9.81])  # the tool's weight as the sensor reads it
    at_rest = [*weight, 0.0, 0.0, 0.0]
    ctrl.intake.tare(at_rest, R)
    for i in range(50):
        ctrl.update(at_rest, i * 0.002, T, R)
    assert ctrl.intake.contact_force(at_rest, T, R) == pytest.approx((0.0, 0.0, 0.0), abs=1e-9)
    # The table pushes the tool up with 10 N: the step shows at once, the filtered force lags behind.
    pressed = [*(weight + R.T @ np.array([0.0, 0.0, 10.0])), 0.0, 0.0, 0.0]
    result = ctrl.update(pressed, 0.1, T, R)
    assert ctrl.intake.contact_force(pressed, T, R) == pytest.approx((0.0, 0.0, 10.0), abs=1e-9)
    assert result.wrench[2] < 1.0
    assert ctrl.intake.contact_force([float("nan"), 0, 0, 0, 0, 0], T, R) is None
    assert ctrl.intake.contact_force(pressed, T, None) is None  # with a tool model the orientation is needed


def test_contact_force_is_the_unfiltered_force_of_the_chain():
    """Sign flips, bias, tool weight and the frame change as the laws' chain has them (filter off)."""
    ctrl = controller(
        tool_mass=0.8, tool_com=[0.01, 0.0, 0.04], lp_filter_enabled=False, ft_x_direction=-1,
        ft_z_direction=-1,
    )
    R = rot([0.3, -0.5, 0.8], 2.1)
    T = np.eye(4)
    T[:3, :3] = rot([0.0, 0.0, 1.0], 0.7)
    T[:3, 3] = [0.1, -0.2, 0.3]
    ctrl.intake.tare([0.5, -1.0, 2.0, 0.01, 0.02, -0.03], R)
    raw = [3.0, -4.0, 7.5, 0.2, -0.1, 0.05]
    code, chain = ctrl.preprocessor.process(raw, T, R)
    assert code == 0
    assert ctrl.intake.contact_force(raw, T, R) == pytest.approx(chain[:3], abs=1e-12)
    from_lists = ctrl.intake.contact_force(np.array(raw), T.tolist(), R.tolist())
    assert from_lists == pytest.approx(chain[:3], abs=1e-12)
