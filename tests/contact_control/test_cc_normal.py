"""The normal law (RX/RY): the tool's axis turns onto the contact normal read from the force, while Z presses.

A plane tilted 15 degrees about Y (20 N/mm) under a tool pointing down; the arm follows each command 20 ms
late. The wrench reaches the controller in the sensor frame, whose z axis is the tool's.
"""

import math
import re

import numpy as np
import pytest
from cc_sim import DT, ClosedLoop, controller, laws, rot
from contact_control.axes import LAW_FORCE_TRACKING, LAW_NORMAL, SAFETY_OK
from contact_control.laws import AxisLaw
from contact_control.normal import NormalFollower, normal_velocity
from contact_control.params import load_settings
from contact_control.request import (
    SET_CARTESIAN_CONTROL_FAILED,
    SET_DOF_FAILED,
    RequestError,
    RequestLimits,
    empty_laws_request,
    empty_request,
    fill_laws_request,
    validate_laws_request,
    validate_request,
)

TILT = math.radians(15.0)
STIFFNESS = 20000.0  # [N/m]
PRESS = AxisLaw(LAW_FORCE_TRACKING, damping=2000.0, velocity=0.01, target=10.0)
NORMAL = AxisLaw(LAW_NORMAL, stiffness=3.0)
DOWN = rot([1.0, 0.0, 0.0], math.pi)  # the tool's axis (sensor z) pointing down


def plane_normal(tilt: float = TILT) -> np.ndarray:
    return np.array([math.sin(tilt), 0.0, math.cos(tilt)])


class Plane:
    """A plane through (0, 0, -0.01) under the tool; `normal` may change at `switch_at` [s]. The force on the
    tool is the plane's push plus, with `mu`, friction against the tool's motion along the plane."""

    def __init__(self, normal: np.ndarray, mu: float = 0.0, switch_at: float | None = None,
                 switched: np.ndarray | None = None) -> None:
        self.normal, self.mu, self.switch_at, self.switched = normal, mu, switch_at, switched
        self.last = None

    def __call__(self, t: float, pose: np.ndarray) -> list[float]:
        n = self.switched if self.switch_at is not None and t >= self.switch_at else self.normal
        depth = float((np.array([0.0, 0.0, -0.01]) - pose[:3, 3]) @ n)
        force = STIFFNESS * depth * n if depth > 0.0 else np.zeros(3)
        if self.mu and depth > 0.0 and self.last is not None:
            slide = pose[:3, 3] - self.last
            slide -= (slide @ n) * n
            if np.linalg.norm(slide) > 1e-9:
                force -= self.mu * np.linalg.norm(force) * slide / np.linalg.norm(slide)
        self.last = pose[:3, 3].copy()
        return [*(pose[:3, :3].T @ force), 0.0, 0.0, 0.0]  # in the sensor (tool) frame


class ToolLoop(ClosedLoop):
    """The closed loop with the sensor turning with the tool (T_control_sensor = the tool's pose)."""

    def run(self, wrench, seconds: float):
        result = None
        for _ in range(round(seconds / DT)):
            result = self.ctrl.update(wrench(self.t, self.pose), self.t, T_control_sensor=self.pose,
                                      eef_pose=self.pose)
            self.results.append(result)
            self._pending.append(np.asarray(result.velocity))
            v = self._pending.popleft()
            self.pose[:3, 3] += v[:3] * DT
            if np.any(v[3:]):
                self.pose[:3, :3] = rot(v[3:], np.linalg.norm(v[3:]) * DT) @ self.pose[:3, :3]
            self.t += DT
        return result


def tool_loop(**params: object) -> ToolLoop:
    pose = np.eye(4)
    pose[:3, :3] = DOWN
    return ToolLoop(controller(**params), pose, lag=0.02)


def off_normal(loop: ToolLoop, normal: np.ndarray) -> float:
    """The angle [deg] between the tool's axis and the inward normal."""
    return math.degrees(math.acos(np.clip(loop.pose[:3, 2] @ -normal, -1.0, 1.0)))


def test_the_tool_turns_onto_a_tilted_planes_normal_while_pressing_10_n():
    loop = tool_loop()
    loop.start(laws(z=PRESS, rx=NORMAL, ry=NORMAL))
    assert off_normal(loop, plane_normal()) == pytest.approx(15.0, abs=0.01)
    result = loop.run(Plane(plane_normal()), 4.0)
    assert result.safety == SAFETY_OK and result.move_active and result.message == ""
    assert off_normal(loop, plane_normal()) < 0.5
    # turned about Y only (the plane is tilted about Y), not about the tool's own axis
    assert abs(loop.pose[1, 2]) < 1e-3
    assert result.wrench[2] == pytest.approx(10.0, abs=0.5)


def test_in_free_air_the_orientation_holds():
    loop = tool_loop()
    loop.start(laws(z=PRESS, rx=NORMAL, ry=NORMAL))
    loop.run(lambda t, pose: [2.5, 0.0, 0.0, 0.0, 0.0, 0.0] if t < 0.5 else [0.0] * 6, 1.0)  # under 3 N
    assert np.allclose(loop.pose[:3, :3], DOWN, atol=1e-9)
    assert loop.pose[2, 3] < -0.005  # while Z approached


def test_a_normal_that_jumps_is_not_followed_and_the_status_says_so():
    loop = tool_loop()
    loop.start(laws(z=PRESS, rx=NORMAL, ry=NORMAL))
    jumped = np.array([-math.sin(TILT), 0.0, math.cos(TILT)])  # 30 degrees away: an edge
    loop.run(Plane(plane_normal(), switch_at=3.0, switched=jumped), 3.0)
    before = loop.pose[:3, :3].copy()
    result = loop.run(Plane(plane_normal(), switch_at=3.0, switched=jumped), 1.0)
    assert re.search(r"normal jumped (2[89]|3[01])\.\d deg", result.message), result.message  # of 30
    assert "not followed" in result.message
    assert result.move_active
    assert math.degrees(math.acos(np.clip((np.trace(before.T @ loop.pose[:3, :3]) - 1) / 2, -1, 1))) < 0.3


def test_a_slowly_turning_normal_is_followed_at_the_rate_limit():
    follower = NormalFollower(min_force=3.0, max_rate=0.5, jump=0.2, friction=0.0)
    down = (0.0, 0.0, -1.0)
    # the move's first normal is taken once the estimate has held still for 0.2 s
    for cycles in (90, 60):
        assert follower.normal is None
        for _ in range(cycles):
            follower.step((0.0, 0.0, 10.0), down, (0.0, 0.0, 0.0), DT)
    assert follower.normal == pytest.approx((0.0, 0.0, 1.0))
    n = plane_normal(0.1)  # 0.1 rad away, inside the jump
    turns = [follower.step(tuple(10.0 * n), down, (0.0, 0.0, 0.0), DT) for _ in range(50)]
    # 50 cycles at 0.5 rad/s: the followed normal has turned 0.05 rad of the 0.1
    assert np.linalg.norm(turns[-1]) == pytest.approx(0.05, abs=1e-6)
    # about +Y: the axis leans to -X, as the normal does
    assert np.allclose(np.asarray(turns[-1]) / np.linalg.norm(turns[-1]), [0.0, 1.0, 0.0])


@pytest.mark.parametrize("mu", [0.3])
def test_friction_while_sliding_tilts_the_estimate_unless_its_coefficient_is_given(mu):
    """Sliding along X across a plane tilted about X: friction leans the force back by atan(mu), and the
    tool with it, unless normal_friction (tuned live) takes it out."""
    normal = np.array([0.0, -math.sin(TILT), math.cos(TILT)])
    slide = AxisLaw(3, damping=0.0, velocity=0.01, max_travel=0.05)  # compliant move along X
    errors = {}
    for given in (0.0, mu):
        loop = tool_loop()
        if given:  # tuned live, as `dynparam set` does
            loop.ctrl.retune(load_settings({"tare_on_startup": False, "normal_friction": given}))
        loop.start(laws(x=slide, z=PRESS, rx=NORMAL, ry=NORMAL))
        loop.run(Plane(normal, mu=mu), 4.0)
        errors[given] = math.degrees(math.atan2(loop.pose[0, 2], -loop.pose[2, 2]))  # lean about Y
    assert abs(errors[0.0]) == pytest.approx(math.degrees(math.atan(mu)), abs=2.0)
    assert abs(errors[mu]) < 1.0


def test_normal_velocity_is_k_theta_within_its_cap():
    assert normal_velocity(AxisLaw(LAW_NORMAL, stiffness=2.0), 0.1) == pytest.approx(0.2)
    assert normal_velocity(AxisLaw(LAW_NORMAL, stiffness=2.0, velocity=0.05), -0.1) == -0.05


def _request(**axes):
    req = fill_laws_request(empty_laws_request(), laws())
    for name, values in axes.items():
        for key, value in values.items():
            setattr(getattr(req, name), key, value)
    return req


def test_the_request_offers_the_normal_law_on_rx_and_ry_only():
    got = validate_laws_request(_request(rx={"law": 6, "stiffness": 2.0}, ry={"law": 6, "stiffness": 2.0}))
    assert [law.law for law in got] == [0, 0, 0, LAW_NORMAL, LAW_NORMAL, 0]
    with pytest.raises(RequestError) as err:
        validate_laws_request(_request(z={"law": 6, "stiffness": 2.0}))
    assert err.value.code == SET_DOF_FAILED and "RX and RY only" in str(err.value)
    with pytest.raises(RequestError) as err:
        validate_laws_request(_request(rx={"law": 6, "stiffness": 0.0}))
    assert "rx.stiffness" in str(err.value)
    with pytest.raises(RequestError) as err:
        validate_laws_request(_request(rx={"law": 6, "stiffness": 1.0, "velocity": 5.0}),
                              RequestLimits(max_angular_velocity=0.5))
    assert err.value.code == SET_CARTESIAN_CONTROL_FAILED and "rx.velocity" in str(err.value)
    old = empty_request()
    old.direction_control_laws.rx.type = 6
    with pytest.raises(RequestError, match="ConfigureLaws only"):
        validate_request(old)
