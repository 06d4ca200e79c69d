"""The contact-force guard on outside twists (jog_arm.contact_guard): pure logic, no ROS."""

import math

import pytest
from jog_arm.contact_guard import ContactGuard
from jog_arm.settings import JogSettings, SettingsError


def guard() -> ContactGuard:
    """A fresh guard (it remembers having reached the limit)."""
    return ContactGuard(max_force=20.0, slow_force=5.0, slow_speed=0.02, timeout=0.25, relief_speed=0.005)


GUARD = guard()
DOWN = (0.0, 0.0, -0.1, 0.0, 0.0, 0.0)  # jogging down at 10 cm/s (the keyboard's speed is 0.2 m/s)
TABLE = (0.0, 0.0, 1.0)  # the table pushes the tool up: +Z


def force(newtons, direction=TABLE):
    return tuple(newtons * d for d in direction)


def test_free_air_and_light_contact_pass_unchanged():
    assert GUARD.limit(DOWN, (0.0, 0.0, 0.0)).twist == DOWN
    result = GUARD.limit(DOWN, force(4.9))
    assert result.twist == DOWN and not result.acted and result.message == ""


def test_pressing_harder_slows_then_stops_motion_into_the_contact():
    speeds = [-guard().limit(DOWN, force(f)).twist[2] for f in (5.0, 10.0, 15.0, 19.9)]
    assert speeds[0] == pytest.approx(0.02)  # capped at slow_speed from 5 N ...
    assert speeds == sorted(speeds, reverse=True) and speeds[3] < 0.001  # ... falling toward 20 N
    stopped = guard().limit(DOWN, force(21.0))
    assert stopped.acted and stopped.blocked
    assert "21.0 N contact force (limit 20 N)" in stopped.message
    assert "moving away is allowed" in stopped.message


def test_over_the_limit_a_push_into_the_contact_backs_off_slowly_then_stays_blocked():
    g = guard()
    # The arm overshot to 60 N: holding the key down now backs off at the relief speed, not faster than asked.
    assert g.limit(DOWN, force(60.0)).twist[2] == pytest.approx(0.005)
    assert g.limit((0.0, 0.0, -0.002, 0.0, 0.0, 0.0), force(60.0)).twist[2] == pytest.approx(0.002)
    # It backs off until 90 % of the limit, then holds (no creeping back toward 20 N) until below slow_force.
    assert g.limit(DOWN, force(18.5)).twist[2] == pytest.approx(0.005)
    held = g.limit(DOWN, force(17.5))
    assert held.twist[2] == 0.0 and held.blocked and "until below 5 N" in held.message
    assert g.limit(DOWN, force(18.5)).twist[2] == 0.0
    assert g.limit(DOWN, force(4.0)).twist == DOWN  # let go of the contact: free again
    assert g.limit(DOWN, force(15.0)).twist[2] == pytest.approx(-0.02 * 5.0 / 15.0)
    assert g.limit(DOWN, force(18.5)).twist[2] < 0.0  # not over the limit this time: slowed, no retreat


def test_moving_away_and_along_the_contact_still_pass_at_the_limit():
    up = (0.0, 0.0, 0.05, 0.0, 0.0, 0.0)
    assert guard().limit(up, force(25.0)).twist == up
    # Only sideways: passes. Down and sideways: stopped whole, backing off slowly instead.
    assert guard().limit((0.03, 0.0, 0.0, 0.0, 0.0, 0.0), force(25.0)).twist[0] == 0.03
    diagonal = guard().limit((0.03, 0.0, -0.05, 0.0, 0.0, 0.0), force(25.0))
    assert diagonal.twist[:3] == pytest.approx((0.0, 0.0, 0.005))
    # A tilted contact (a wall pushing back along +X and +Z): only the component against the force changes.
    wall = force(25.0, (math.sqrt(0.5), 0.0, math.sqrt(0.5)))
    cut = guard().limit((-0.1, 0.0, 0.0, 0.0, 0.0, 0.0), wall).twist
    assert cut[:3] == pytest.approx(tuple(0.005 * w / 25.0 for w in wall))  # straight back along F
    # Below the limit only the part into the contact is capped: a push along -X against that wall keeps
    # its component along the wall.
    tilted = force(10.0, (math.sqrt(0.5), 0.0, math.sqrt(0.5)))
    slowed = guard().limit((-0.1, 0.0, 0.0, 0.0, 0.0, 0.0), tilted)
    assert slowed.twist[0] - slowed.twist[2] == pytest.approx(-0.1)  # along the wall: unchanged
    into = -(slowed.twist[0] + slowed.twist[2]) * math.sqrt(0.5)
    assert into == pytest.approx(0.02 * (20.0 - 10.0) / 15.0)  # into it: capped
    # At the limit a rotation could lever the tool into the surface: it is removed.
    assert guard().limit((0.0, 0.0, 0.0, 0.0, 0.3, 0.0), force(25.0)).twist == (0.0,) * 6


def test_never_faster_than_asked():
    for f in (0.0, 6.0, 12.0, 19.0, 25.0, 60.0):
        for twist in (DOWN, (0.0, 0.0, -0.01, 0.0, 0.0, 0.0), (0.02, -0.01, 0.0, 0.1, 0.0, 0.0)):
            out = guard().limit(twist, force(f)).twist
            assert sum(o * o for o in out) <= sum(t * t for t in twist) + 1e-12, (f, twist, out)


def test_stale_or_missing_force():
    stale = GUARD.limit(DOWN, force(1.0), age=0.3)
    assert stale.twist == (0.0,) * 6 and stale.blocked and "0.300 s old" in stale.message
    bad = GUARD.limit(DOWN, (math.nan, 0.0, 0.0))
    assert bad.twist == (0.0,) * 6 and "not finite" in bad.message
    # Never received (a stack without a sensor): jogging works, and the result says it is unguarded.
    none = GUARD.limit(DOWN, None)
    assert none.twist == DOWN and "not guarded" in none.message


def test_settings_are_validated_naming_the_key():
    settings = JogSettings.from_params({})
    assert (settings.contact_guard_enabled, settings.contact_guard_max_force) == (True, 20.0)
    with pytest.raises(SettingsError, match="contact_guard_slow_force"):
        JogSettings.from_params({"contact_guard_slow_force": 25.0})
    with pytest.raises(SettingsError, match="contact_guard_max_force"):
        JogSettings.from_params({"contact_guard_max_force": 0.0})
    with pytest.raises(ValueError, match="slow_force"):
        ContactGuard(10.0, 10.0, 0.02, 0.25)
