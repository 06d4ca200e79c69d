"""Force tracking (V = (F - F_target) / b): an axis presses with a set contact force while the others move.

The surface is a stiff table (20 N/mm, a position-controlled arm on a hard surface) 1 cm below the start,
and the simulated arm follows each command 20 ms late, as in test_cc_exceeded. F is the force the table
puts on the tool along +Z, so pressing down with 10 N is a target of +10 N.
"""

from dataclasses import replace

import numpy as np
import pytest
from cc_sim import DT, ClosedLoop, controller, laws
from contact_control.axes import (
    END_FT_VIOLATION,
    END_MAX_TRAVEL,
    EXCEEDED_MOVE_AWAY,
    LAW_COMPLIANT_MOVE,
    LAW_FORCE_TRACKING,
    LAW_PATH,
    SAFETY_OK,
)
from contact_control.laws import AxisLaw, guard_pressing, law_velocity, shape_velocity
from contact_control.params import load_settings
from contact_control.request import (
    SET_CARTESIAN_CONTROL_FAILED,
    SET_CONTROL_FORCE_FAILED,
    SET_DOF_FAILED,
    RequestError,
    RequestLimits,
    empty_laws_request,
    empty_request,
    fill_laws_request,
    fill_request,
    validate_laws_request,
    validate_request,
)

TARGET = 10.0  # [N], pressing down on the table
STIFFNESS = 20000.0  # [N/m]
TABLE_Z = -0.01  # [m] at x = 0
B = 2000.0  # [N/(m/s)]: loop gain STIFFNESS / B = 10 1/s, well damped with the 20 ms lag
TOLERANCE = 0.5  # [N] on the held force (the law's deadband is 0.2 N)
PRESS = AxisLaw(LAW_FORCE_TRACKING, damping=B, velocity=0.01, target=TARGET)
TUNING = load_settings({}).tuning(False)


def table(slope: float = 0.0, step_at: float | None = None, step: float = 0.0):
    """The wrench of a table whose height rises by `slope` per metre of X (and `step` from time `step_at`)."""

    def wrench(t, pose):
        height = TABLE_Z + slope * pose[0, 3] + (step if step_at is not None and t >= step_at else 0.0)
        depth = height - pose[2, 3]
        return [0.0, 0.0, STIFFNESS * depth if depth > 0.0 else 0.0, 0.0, 0.0, 0.0]

    return wrench


def forces(loop: ClosedLoop, since: float) -> np.ndarray:
    return np.array([r.wrench[2] for r in loop.results[round(since / DT):]])


def test_law_moves_toward_the_contact_until_the_force_reaches_the_target():
    # Free air: no deadband around zero force; it approaches at its approach speed, down toward the table.
    assert law_velocity(PRESS, TUNING, 0.0, 0.0) == pytest.approx(-0.01)
    # In contact: (F - F_target) / b less the tracking deadband (0.2 N), pressing harder when short of the
    # target, backing off above it.
    assert law_velocity(PRESS, TUNING, 8.0, 0.0) == pytest.approx(-1.8 / B)
    assert law_velocity(PRESS, TUNING, 13.0, 0.0) == pytest.approx(2.8 / B)
    # Within the deadband of the target it holds, and the velocity is continuous at its edge (a step to
    # 0.2 N / b there made a relay that swung a pressed replay's force by +-2 N).
    assert law_velocity(PRESS, TUNING, 10.15, 0.0) == 0.0
    assert abs(law_velocity(PRESS, TUNING, 10.2001, 0.0)) < 1e-3 / B
    assert abs(law_velocity(PRESS, TUNING, 9.7999, 0.0)) < 1e-3 / B
    # A small correction is kept (no 5 mm/s minimum velocity: a stiff surface needs a large b).
    assert shape_velocity(law_velocity(PRESS, TUNING, 12.0, 0.0), 0.0009, TUNING, DT, floor=False) == 0.0009
    # Pressing up against a ceiling (target -10 N): the mirror image.
    up = replace(PRESS, target=-TARGET)
    assert law_velocity(up, TUNING, 0.0, 0.0) == pytest.approx(0.01)
    assert law_velocity(up, TUNING, -13.0, 0.0) == pytest.approx(-2.8 / B)
    # A small b does not make the approach faster: out of contact it is the approach speed, which sets the
    # overshoot on touching (10 / 800 = 12.5 mm/s touched a simulated UR3's block with 26 N).
    soft = replace(PRESS, damping=800.0, velocity=0.005)
    assert law_velocity(soft, TUNING, 0.0, 0.0) == pytest.approx(-0.005)
    assert law_velocity(soft, TUNING, 4.0, 0.0) == pytest.approx(-0.005)
    assert law_velocity(soft, TUNING, 6.0, 0.0) == pytest.approx(-3.8 / 800.0)


def test_presses_with_the_target_force_and_holds_it():
    loop = ClosedLoop(controller(), lag=0.02)
    loop.start(laws(z=PRESS))
    loop.run(table(), 5.0)
    held = forces(loop, 3.0)
    assert np.all(np.abs(held - TARGET) <= TOLERANCE), (held.min(), held.max())
    assert max(r.wrench[2] for r in loop.results) < 25.0  # never near the global limit on the way in
    assert loop.results[-1].safety == SAFETY_OK and loop.results[-1].move_active
    assert loop.pose[2, 3] < TABLE_Z  # it is in the table by TARGET / STIFFNESS
    assert loop.pose[2, 3] == pytest.approx(TABLE_Z - TARGET / STIFFNESS, abs=0.2 / STIFFNESS + 1e-6)



def test_the_unfiltered_force_caps_pressing_and_never_pulls_back():
    # In contact by the unfiltered force (>= half the target): at most (F_target - F) / b, deadband as in the
    # law; at or past the target's band nothing presses.
    assert guard_pressing(PRESS, TUNING, -0.01, 6.0) == pytest.approx(-3.8 / B)
    assert guard_pressing(PRESS, TUNING, -0.01, 9.9) == 0.0
    assert guard_pressing(PRESS, TUNING, -0.01, 30.0) == 0.0
    # A slower press than the cap is kept; pulling back is the filtered law's alone (noise cannot make the
    # axis retreat); out of contact by the unfiltered force the approach is untouched.
    assert guard_pressing(PRESS, TUNING, -0.0005, 6.0) == -0.0005
    assert guard_pressing(PRESS, TUNING, 0.002, 30.0) == 0.002
    assert guard_pressing(PRESS, TUNING, -0.01, 4.9) == -0.01
    # Pressing up against a ceiling: the mirror image; no target, no contact to guard.
    up = replace(PRESS, target=-TARGET)
    assert guard_pressing(up, TUNING, 0.01, -6.0) == pytest.approx(3.8 / B)
    assert guard_pressing(up, TUNING, 0.01, -12.0) == 0.0
    assert guard_pressing(up, TUNING, -0.002, -30.0) == -0.002
    assert guard_pressing(replace(PRESS, target=0.0), TUNING, -0.01, 50.0) == -0.01


def touch(guard: bool, stiffness: float = 60000.0) -> tuple[np.ndarray, ClosedLoop]:
    """Presses at 5 mm/s on a table `stiffness` [N/m] stiff (the arm 10 ms late); the true force per cycle."""
    true: list[float] = []

    def stiff_table(t, pose):
        depth = TABLE_Z - pose[2, 3]
        true.append(stiffness * depth if depth > 0.0 else 0.0)
        return [0.0, 0.0, true[-1], 0.0, 0.0, 0.0]

    loop = ClosedLoop(controller(force_tracking_fast_guard=guard), lag=0.01)
    loop.start(laws(z=replace(PRESS, velocity=0.005)))
    loop.run(stiff_table, 4.0)
    return np.array(true), loop


def test_touching_a_stiff_surface_stops_pressing_before_the_filter_has_seen_the_contact():
    # 60 N/mm, three times the README's arm on a table (the simulated SO-100 and UR3 on their blocks measured
    # 90-130 N/mm): the 5 Hz filter's 45 ms delay let the approach run on.
    unguarded, _ = touch(False)
    assert unguarded.max() > 20.0  # what tripped the SO-100's limits
    true, loop = touch(True)
    assert true.max() < 12.0
    contact = int(np.argmax(true > 0.0))
    held = true[contact + round(1.0 / DT):]  # a second after touching: on the target, and staying there
    assert np.all(np.abs(held - TARGET) <= TOLERANCE), (held.min(), held.max())
    assert loop.results[-1].move_active
    # Without the guard the same loop never settles: it bounces on the table.
    assert np.ptp(unguarded[contact + round(1.0 / DT):]) > 5.0


def test_noise_on_the_unfiltered_force_barely_moves_the_held_force():
    # A UR e-series wrench's noise (0.2-0.6 N, ../shared/realdata) at 2 N: the guard only ever slows pressing,
    # so the true force settles a little low, within the law's deadband.
    rng = np.random.default_rng(7)
    true: list[float] = []

    def noisy_table(t, pose):
        depth = TABLE_Z - pose[2, 3]
        true.append(STIFFNESS * depth if depth > 0.0 else 0.0)
        return [0.0, 0.0, true[-1] + rng.normal(0.0, 2.0), 0.0, 0.0, 0.0]

    loop = ClosedLoop(controller(), lag=0.02)
    loop.start(laws(z=PRESS))
    loop.run(noisy_table, 6.0)
    held = np.array(true[-round(3.0 / DT):])
    assert held.mean() == pytest.approx(TARGET, abs=0.3)
    assert np.all(np.abs(held - TARGET) <= 2 * TOLERANCE), (held.min(), held.max())

def press_then_move_x(slope: float) -> tuple[ClosedLoop, float]:
    """Presses for 3 s, then adds an X compliant move (0.02 m/s) for 3 s; returns the loop and X's start."""
    loop = ClosedLoop(controller(), lag=0.02)
    loop.start(laws(z=PRESS))
    loop.run(table(slope=slope), 3.0)
    x0 = loop.pose[0, 3]
    # Bumpless: the same law on Z keeps pressing while X starts.
    loop.start(laws(z=PRESS, x=AxisLaw(LAW_COMPLIANT_MOVE, velocity=0.02, max_travel=0.1)))
    loop.run(table(slope=slope), 3.0)
    return loop, x0


def test_holds_the_force_on_a_flat_surface_while_x_moves_on_its_own():
    loop, x0 = press_then_move_x(0.0)
    assert loop.pose[0, 3] - x0 == pytest.approx(0.06, abs=0.002)  # 3 s at 0.02 m/s: Z did not slow it
    assert loop.pose[1, 3] == 0.0
    held = forces(loop, 3.0)
    assert np.all(np.abs(held - TARGET) <= TOLERANCE), (held.min(), held.max())


def test_on_a_rising_surface_the_force_settles_b_times_the_rise_rate_above_the_target():
    # V = (F - F_target) / b has no integral action: to rise at the surface's rate r the axis needs
    # F - F_target = b r (here 0.05 * 0.02 m/s * 2000 = 2 N). The README says so: a larger b, a larger error.
    loop, x0 = press_then_move_x(0.05)
    assert loop.pose[0, 3] - x0 == pytest.approx(0.06, abs=0.002)
    held = forces(loop, 3.5)  # after X got up to speed
    assert held.mean() == pytest.approx(TARGET + 0.05 * 0.02 * B, abs=TOLERANCE)
    assert np.ptp(held) < TOLERANCE
    # Z rose with the surface, in contact all along.
    assert loop.pose[2, 3] == pytest.approx(TABLE_Z + 0.05 * loop.pose[0, 3] - held[-1] / STIFFNESS, abs=1e-4)


def reference(loop: ClosedLoop, x: float, t: float) -> None:
    """The path law's reference at `x` on the X axis, moving at SPEED."""
    loop.ctrl.set_path_reference((x, 0.0, 0.0), (0, 0, 0, 1), (SPEED, 0, 0, 0, 0, 0), t)


def press_then_follow_x(slope: float, **params: object) -> tuple[ClosedLoop, float]:
    """Presses for 3 s, then X follows a path reference moving at SPEED for 8 s (force tracking beside a path
    law: the integral term runs); returns the loop and X's start."""
    loop = ClosedLoop(controller(**params), lag=0.02)
    loop.start(laws(z=PRESS))
    loop.run(table(slope=slope), 3.0)
    x0, t0 = loop.pose[0, 3], loop.t

    def moving_table(t, pose):
        reference(loop, x0 + SPEED * (t - t0), t)
        return table(slope=slope)(t, pose)

    loop.ctrl.set_path_reference((x0, 0.0, 0.0), (0, 0, 0, 1), (0,) * 6, t0)
    loop.start(laws(z=PRESS, x=AxisLaw(LAW_PATH, stiffness=5.0)))
    loop.run(moving_table, 8.0)
    return loop, x0


SPEED = 0.02  # [m/s] the path's


def test_beside_a_path_the_integral_term_brings_a_rising_surface_to_the_target():
    # The same 2 N the proportional law leaves on a 5 % rise (the test above) decays with the integral's
    # time constant (1 s) once X slides along its path.
    loop, x0 = press_then_follow_x(0.05)
    assert loop.pose[0, 3] - x0 == pytest.approx(SPEED * 8.0, abs=0.002)
    held = forces(loop, 3.0 + 5.0)  # the last 3 s
    assert held.mean() == pytest.approx(TARGET, abs=0.3)
    assert np.ptp(held) < TOLERANCE
    off, _ = press_then_follow_x(0.05, force_tracking_path_integral=0.0)
    assert forces(off, 3.0 + 5.0).mean() == pytest.approx(TARGET + 0.05 * SPEED * B, abs=TOLERANCE)


def test_the_integral_term_holds_a_flat_surface_and_never_winds_up_off_it():
    loop, _ = press_then_follow_x(0.0)
    held = forces(loop, 3.0)
    assert np.all(np.abs(held - TARGET) <= TOLERANCE), (held.min(), held.max())
    # The table falls away 5 mm: out of contact the axis approaches at its approach speed, no faster, and
    # touches again without overshooting more than a plain touch does.
    x0, t0 = loop.pose[0, 3], loop.t

    def falling(t, pose):
        reference(loop, x0 + SPEED * (t - t0), t)
        return table(step_at=t0, step=-0.005)(t, pose)

    loop.run(falling, 3.0)
    after = loop.velocities()[round(t0 / DT):, 2]
    assert after.min() >= -PRESS.velocity - 1e-9  # never faster than the approach speed toward the table
    again = forces(loop, t0 + 1.5)
    assert again.max() < TARGET + 3.0 and again[-1] == pytest.approx(TARGET, abs=TOLERANCE)


def test_a_force_limit_ends_the_press_and_move_away_lets_go():
    loop = ClosedLoop(controller(), lag=0.02)
    loop.start(laws(z=replace(PRESS, force_limit=18.0, exceeded_action=EXCEEDED_MOVE_AWAY)))
    loop.run(table(step_at=3.0, step=0.0005), 5.0)  # the surface rises 0.5 mm at once (10 N more)
    ended = next(i for i, r in enumerate(loop.results) if not r.move_active)
    assert loop.results[ended].end_conditions[2] == END_FT_VIOLATION
    assert all(r.velocity[2] >= 0.0 for r in loop.results[ended:])  # never pressed further
    assert table(step_at=3.0, step=0.0005)(loop.t, loop.pose)[2] < 0.5 * 18.0  # released


def test_max_travel_ends_the_press():
    loop = ClosedLoop(controller(), lag=0.02)
    loop.start(laws(z=replace(PRESS, max_travel=0.005)))  # the table is 1 cm down: never reached
    loop.run(table(), 2.0)
    assert loop.results[-1].end_conditions[2] == END_MAX_TRAVEL
    assert abs(loop.pose[2, 3]) < 0.006 and loop.results[-1].velocity[2] == 0.0


def laws_request(**z):
    req = empty_laws_request()
    for key, value in {"law": LAW_FORCE_TRACKING, "damping": B, "target_force": TARGET, **z}.items():
        setattr(req.z, key, value)
    return req


LIMITS = RequestLimits.from_settings(load_settings({}))


def test_configure_laws_takes_force_tracking_with_the_default_approach_speed():
    law = validate_laws_request(laws_request(), LIMITS)[2]
    assert law == AxisLaw(LAW_FORCE_TRACKING, damping=B, velocity=0.01, target=TARGET)
    # Round trip through the request (the GUI writes requests this way).
    written = fill_laws_request(empty_laws_request(), [AxisLaw()] * 2 + [law] + [AxisLaw()] * 3)
    assert validate_laws_request(written, LIMITS)[2] == law


@pytest.mark.parametrize(
    "fields, code, text",
    [
        ({"damping": 0.0}, SET_CARTESIAN_CONTROL_FAILED, "Z reads z.damping; got 0.0"),
        ({"target_force": float("nan")}, SET_CONTROL_FORCE_FAILED, "z.target_force"),
        ({"target_force": 30.0}, SET_CONTROL_FORCE_FAILED, "below the global limit 25.0 N"),
        ({"force_limit": 8.0}, SET_CONTROL_FORCE_FAILED, "must exceed |target_force| 10 N"),
        ({"velocity": -0.01}, SET_CARTESIAN_CONTROL_FAILED, "z.velocity; got -0.01"),
        ({"velocity": 1.0}, SET_CARTESIAN_CONTROL_FAILED, "exceeds max velocity"),
    ],
)
def test_bad_force_tracking_requests_are_refused_naming_the_field(fields, code, text):
    with pytest.raises(RequestError) as err:
        validate_laws_request(laws_request(**fields), LIMITS)
    assert err.value.code == code and text in err.value.message, err.value.message


def test_the_original_message_has_no_force_tracking():
    req = empty_request()
    req.direction_control_laws.z.type = LAW_FORCE_TRACKING
    req.cart_impedance_params.damping.translational.z = B
    with pytest.raises(RequestError) as err:
        validate_request(req, LIMITS)
    assert err.value.code == SET_DOF_FAILED and "configure_laws" in err.value.message
    with pytest.raises(ValueError, match="use ConfigureLaws"):
        fill_request(empty_request(), [AxisLaw()] * 2 + [PRESS] + [AxisLaw()] * 3)
