"""Lockstep's rules without ROS: when the loop may step, how an echo's stamp is placed, waiting, giving up."""

from __future__ import annotations

import threading

import pytest
from mujoco_driver.lockstep import Lockstep

MS = 1_000_000  # ns


def test_a_driven_arm_steps_up_to_the_lead_past_its_newest_command_then_holds():
    lock = Lockstep(lead=0.01)
    assert lock.hold(5.0) == ""  # nothing commands the arm: free running
    lock.command(1.000, moving=True)
    assert lock.hold(1.0099) == ""
    assert lock.hold(1.011) == "velocity command"
    lock.command(1.011, moving=True)
    assert lock.hold(1.011) == ""


def test_a_zero_velocity_or_a_trajectory_never_holds_the_simulation():
    lock = Lockstep(lead=0.01)
    lock.command(1.0, moving=False)
    assert lock.hold(9.0) == ""
    lock.command(1.0, moving=True)
    lock.command(1.002, moving=False)  # the trajectory or zero command after it
    assert lock.hold(9.0) == ""


def test_an_echo_is_placed_at_the_published_state_it_answers_and_holds_when_late():
    lock = Lockstep(lead=0.01)
    for k in range(20):  # states every 2 ms, stamped on another clock (wall time)
        lock.published(1000 * MS + 2 * k * MS, 0.002 * k)
    lock.command(0.038, moving=True)
    assert lock.hold(0.038) == ""  # no echo seen yet: commands only
    lock.echo(1000 * MS + 20 * MS)  # answered the state of t = 0.020 s
    assert lock.hold(0.0299) == ""
    assert lock.hold(0.031) == "echo"
    lock.echo(1000 * MS + 35 * MS)  # between two stamps: the newest state at or before it, t = 0.034 s
    assert lock.hold(0.0439) == ""
    assert lock.hold(0.0441) == "echo"
    lock.echo(1000 * MS + 30 * MS)  # older than the newest echo: ignored
    assert lock.hold(0.0441) == "echo"
    lock.echo(1000 * MS + 38 * MS)
    assert lock.hold(0.0481) == "velocity command"  # answered, but the command is late now


def test_an_echo_older_than_every_remembered_state_is_ignored():
    lock = Lockstep(lead=0.01, history=3)
    for k in range(10):
        lock.published(k * MS, k * 0.001)
    lock.command(0.009, moving=True)
    lock.echo(2 * MS)  # forgotten (only 7, 8, 9 ms remembered)
    assert lock.hold(0.019) == ""


def test_wait_returns_when_the_stack_answers_and_times_out_when_it_does_not():
    lock = Lockstep(lead=0.01)
    lock.command(1.0, moving=True)
    assert not lock.wait(1.02, timeout=0.05)
    answer = threading.Timer(0.05, lambda: lock.command(1.02, moving=True))
    answer.start()
    try:
        assert lock.wait(1.02, timeout=10.0)
    finally:
        answer.join()


def test_giving_up_runs_freely_until_the_stack_speaks_again():
    lock = Lockstep(lead=0.01)
    lock.published(10 * MS, 0.010)
    lock.command(0.010, moving=True)
    lock.echo(10 * MS)
    assert lock.hold(0.5) == "velocity command"
    lock.give_up()
    assert lock.hold(0.5) == ""
    lock.command(0.5, moving=True)  # commands again, the echo still silent: held by commands only
    assert lock.hold(0.5099) == ""
    assert lock.hold(0.52) == "velocity command"
    lock.published(500 * MS, 0.5)
    lock.echo(500 * MS)  # and the echo back: held by both again
    lock.command(0.6, moving=True)
    assert lock.hold(0.6) == "echo"


def test_reset_forgets_every_time():
    lock = Lockstep(lead=0.01)
    lock.published(5 * MS, 5.0)
    lock.command(5.0, moving=True)
    lock.echo(5 * MS)
    lock.reset()
    assert lock.hold(0.0) == ""
    lock.command(0.0, moving=True)
    lock.echo(5 * MS)  # no state remembered since the reset
    assert lock.hold(0.01) == ""


@pytest.mark.parametrize("lead, history", [(0.0, 10), (-1.0, 10), (float("nan"), 10), (0.01, 0)])
def test_bad_settings_are_refused(lead, history):
    with pytest.raises(ValueError, match="lead and history"):
        Lockstep(lead, history)
