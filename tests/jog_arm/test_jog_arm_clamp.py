"""Clamp release (ISO/TS 15066): a contact force held over the body region's quasi-static limit, or over
clamp_push_force while the contact guard holds a push into it back, is a clamp; the arm backs off along the
force until it is below 10 N, whatever it is told meanwhile. A short peak is not a clamp. The rules on their
own, then in the compliant pipeline with a perfect arm pressing a hand of 75 N/mm (ISO/TS 15066's)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from harness.pipeline_cell import DT, Cell
from jog_arm.clamp import ClampRelease
from jog_arm.status import StatusCode

pytestmark = pytest.mark.cobot_safety

HAND_STIFFNESS = 75e3  # [N/m] ISO/TS 15066 Annex A


def test_a_sustained_force_over_the_limit_is_released_and_a_spike_is_not():
    clamp = ClampRelease(140.0, 20.0, 0.05, 0.02, 10.0)  # released below 10 N here (the default: 5 N)
    assert clamp.check((0.0, 0.0, 200.0), 0.0, 0.25, 0.0) is None  # a 200 N sample
    assert clamp.check((0.0, 0.0, 5.0), 0.0, 0.25, 0.01) is None and not clamp.active  # gone: a spike
    assert clamp.check((0.0, 0.0, 150.0), 0.0, 0.25, 0.02) is None  # over: the hold starts
    assert clamp.check((0.0, 0.0, 150.0), 0.0, 0.25, 0.06) is None  # 40 ms: not yet
    assert clamp.check((0.0, 90.0, 120.0), 0.0, 0.25, 0.07) == pytest.approx((0.0, 0.012, 0.016))  # along F
    assert clamp.active and "the hand's 140 N" in clamp.limit_words("hand")
    assert clamp.check((0.0, 0.0, 11.0), 0.0, 0.25, 0.3) == pytest.approx((0.0, 0.0, 0.02))  # still >= 10 N
    assert clamp.check((0.0, 0.0, 9.0), 0.0, 0.25, 0.4) is None and not clamp.active  # released
    assert clamp.check((0.0, 0.0, 150.0), 0.0, 0.25, 0.41) is None  # a new clamp needs a new hold


def test_while_a_push_is_held_back_the_push_force_counts_and_no_force_releases_nothing():
    clamp = ClampRelease(140.0, 15.0, 0.05, 0.02, 10.0)  # released below 10 N here (the default: 3 N)
    for t in (0.0, 0.03):
        assert clamp.check((0.0, 0.0, 60.0), 0.0, 0.25, t) is None  # 60 N: under the hand's limit
    assert clamp.check((0.0, 0.0, 14.9), 0.0, 0.25, 0.04, pushed=True) is None  # under the push force
    assert clamp.check((0.0, 0.0, 15.0), 0.0, 0.25, 0.05, pushed=True) is None  # the hold starts
    assert clamp.check((0.0, 0.0, 15.0), 0.0, 0.25, 0.11, pushed=True) is not None
    assert clamp.by_push and "15 N while a push into it was held back" in clamp.limit_words("hand")
    other = ClampRelease(140.0, 20.0, 0.05, 0.02, 10.0)
    assert other.check((0.0, 0.0, 300.0), 0.5, 0.25, 0.0) is None  # stale: which way is away is unknown
    assert other.check((math.nan, 0.0, 300.0), 0.0, 0.25, 0.1) is None
    assert other.check(None, 0.0, 0.25, 0.2) is None and not other.active


class HandCell:
    """The UR5's pipeline and a perfect arm whose tool presses a hand (75 N/mm) under it."""

    def __init__(self, robot: str, pressed: float, jog: dict | None = None) -> None:
        self.cell = c = Cell(robot, jog_overrides=jog)
        for _ in range(150):  # zeroed on the tool's weight
            c.step((0.0, 0.0, 0.0))
        assert c.pipeline.contact.ctrl.last_result.safety == 0
        self.surface = self.tip_z() + pressed  # the hand's top: `pressed` [m] above the tool tip
        self.forces: list[float] = []
        self.statuses: list[tuple[int, str]] = []

    def tip_z(self) -> float:
        return float(self.cell.pose("tool_tip")[2, 3])

    def force(self) -> float:
        return HAND_STIFFNESS * max(0.0, self.surface - self.tip_z())

    def run(self, seconds: float, twist: tuple[float, ...] | None = None) -> None:
        c, p = self.cell, self.cell.pipeline
        for _ in range(round(seconds / DT)):
            f = self.force()
            self.forces.append(f)
            c.step((0.0, 0.0, f))
            if twist is not None:
                c._apply(p.on_twist(twist, c.cc.fixed_frame, c.t, c.t))
            last = p.jog.last_cycle
            if last is not None:
                self.statuses.append((int(last.status), last.message))


@pytest.mark.parametrize("robot", ["ur5", "panda"])
def test_a_hand_pressed_at_225_newtons_is_released_below_10_newtons_within_a_second(robot):
    hand = HandCell(robot, pressed=0.003)  # 225 N from the start, nothing commanded
    z0 = hand.tip_z()
    hand.run(1.0)
    forces = np.array(hand.forces)
    below = int(np.argmax(forces < 10.0))
    assert forces[0] == pytest.approx(225.0, rel=0.01) and forces[below] < 10.0 and below > 0
    print(f"\n{robot}: 225 N released below 10 N after {below * DT:.3f} s, tool up "
          f"{(hand.tip_z() - z0) * 1e3:.2f} mm")
    assert below * DT < 1.0
    assert max(forces[below:]) < 10.0  # and it stays released
    assert 0.0025 < hand.tip_z() - z0 < 0.006  # backed off out of the hand, not far beyond
    codes = [code for code, _ in hand.statuses]
    assert StatusCode.CLAMP_RELEASE in codes
    message = next(m for code, m in hand.statuses if code == StatusCode.CLAMP_RELEASE)
    assert "hand's 140 N" in message and "below 3 N" in message
    assert any("clamp released" in m for _, m in hand.statuses[codes.index(StatusCode.CLAMP_RELEASE):])


def test_a_100_newton_press_is_not_a_clamp():
    hand = HandCell("ur5", pressed=0.0013)  # 98 N: under the hand's 140 N, nothing pushing
    z0 = hand.tip_z()
    hand.run(0.5)
    assert abs(hand.tip_z() - z0) < 1e-6 and StatusCode.CLAMP_RELEASE not in [c for c, _ in hand.statuses]


def test_a_push_into_the_hand_that_overshoots_the_guard_is_released_though_the_push_goes_on():
    hand = HandCell("ur5", pressed=-0.002)  # the hand 2 mm below the tool
    hand.run(0.4, twist=(0.0, 0.0, -0.1, 0.0, 0.0, 0.0))  # an outside jog down at 0.1 m/s, held
    forces = np.array(hand.forces)
    peak = int(np.argmax(forces))
    print(f"\nUR5 jog at 0.1 m/s into the hand: peak {forces[peak]:.0f} N, released after "
          f"{(int(np.argmax(forces[peak:] < 10.0))) * DT:.3f} s")
    assert forces[peak] > 20.0  # the guard (20 N) could not stop the arm in time
    released = peak + int(np.argmax(forces[peak:] < 10.0))
    assert forces[released] < 10.0 and (released - peak) * DT < 1.0  # released while the key is held
    assert StatusCode.CLAMP_RELEASE in [c for c, _ in hand.statuses]
    # The key still held moves nothing after the clamp: it must be let go of first.
    assert max(forces[released:]) < 10.0
    assert any("let go of the key" in m for _, m in hand.statuses[released:])
    z = hand.tip_z()
    hand.run(0.2, twist=(0.0, 0.0, 0.02, 0.0, 0.0, 0.0))  # another key at once, away from the hand: moves
    assert hand.tip_z() > z + 0.002
    hand.run(0.2)  # let go
    pressed = len(hand.forces)
    hand.run(1.5, twist=(0.0, 0.0, -0.01, 0.0, 0.0, 0.0))  # pressed again, slowly, the key held
    again = np.array(hand.forces[pressed:])
    # The guard slows the push from its 2 N on; held back over clamp_push_force (10 N), it is a clamp too.
    assert 10.0 <= again.max() < 20.0 and again[-1] < 3.0
    assert StatusCode.CLAMP_RELEASE in [code for code, _ in hand.statuses[pressed:]]


def test_a_slow_push_is_released_where_the_guard_would_have_held_it_and_off_it_holds():
    """A held 1 cm/s jog onto the hand: the guard's slow zone lands it at its 20 N and holds it there while
    the key is held. With the collaborative setting on the push held back over clamp_push_force is a clamp,
    released below 3 N; with the region `off` the guard holds it under 20 N."""
    ends = {}
    for region in ("hand", "off"):
        hand = HandCell("ur5", pressed=-0.002, jog={"collaborative_region": region})
        hand.run(2.0, twist=(0.0, 0.0, -0.01, 0.0, 0.0, 0.0))
        forces = np.array(hand.forces)
        ends[region] = (float(forces.max()), float(forces[-250:].mean()))
        print(f"\nUR5 jog at 0.01 m/s into the hand, region {region}: peak {ends[region][0]:.1f} N, "
              f"the last 0.5 s {ends[region][1]:.1f} N")
    assert ends["hand"][0] < 20.0 and ends["hand"][1] < 3.0
    assert 15.0 < ends["off"][1] <= 20.0


def test_a_push_stopped_at_the_contact_brakes_at_the_contact_stop_scale():
    """The same held jog into the hand with the contact stop's braking (5 x the joints' 3 rad/s^2) and
    without it (1 x): the harder stop pins the hand with far less force."""
    peaks = {}
    for scale in (1.0, 5.0):
        hand = HandCell("ur5", pressed=-0.002, jog={"contact_stop_scale": scale})
        hand.run(0.3, twist=(0.0, 0.0, -0.1, 0.0, 0.0, 0.0))
        peaks[scale] = max(hand.forces)
    print(f"\nUR5 jog at 0.1 m/s into the hand: peak {peaks[1.0]:.0f} N braking at 1 x, "
          f"{peaks[5.0]:.0f} N at 5 x")
    assert peaks[5.0] < 0.6 * peaks[1.0]
    assert peaks[5.0] < 140.0  # under the hand's quasi-static limit


def test_a_retreat_the_force_does_not_follow_stops_after_its_travel():
    clamp = ClampRelease(140.0, 10.0, 0.05, 0.02, 3.0, travel=0.05)
    for t in (0.0, 0.06):
        clamp.check((0.0, 0.0, 60.0), 0.0, 0.25, t, pushed=True)
    assert clamp.active
    assert clamp.check((0.0, 0.0, 60.0), 0.0, 0.25, 2.5) is not None  # 2.44 s at 0.02 m/s: 48.8 mm
    assert clamp.check((0.0, 0.0, 60.0), 0.0, 0.25, 2.6) is None and clamp.stuck and not clamp.active
    assert clamp.check((0.0, 0.0, 200.0), 0.0, 0.25, 3.0, pushed=True) is None  # no new clamp while stuck
    assert clamp.check((0.0, 0.0, 1.0), 0.0, 0.25, 3.1) is None and not clamp.stuck  # the force let go


class StuckSensorCell(HandCell):
    """The same pipeline whose sensor reads 60 N up whatever the tool does."""

    def force(self) -> float:
        return 60.0


def test_a_stuck_sensor_stops_the_clamps_retreat_after_5_cm_and_says_why():
    cell = StuckSensorCell("ur5", pressed=-0.01)
    z0 = cell.tip_z()
    cell.run(0.3, twist=(0.0, 0.0, -0.02, 0.0, 0.0, 0.0))  # a held jog down: the guard holds it, a clamp
    assert StatusCode.CLAMP_RELEASE in [code for code, _ in cell.statuses]
    cell.run(3.0, twist=(0.0, 0.0, -0.02, 0.0, 0.0, 0.0))
    up = cell.tip_z() - z0
    cell.run(1.0)
    print(f"\nUR5, a sensor stuck at 60 N: backed off {up * 1e3:.1f} mm, then "
          f"{(cell.tip_z() - z0) * 1e3:.1f} mm")
    assert 0.045 < up < 0.06 and abs(cell.tip_z() - z0 - up) < 0.002  # 5 cm, then it stays
    assert any("backed off 50 mm and the contact force still reads" in m for _, m in cell.statuses)
