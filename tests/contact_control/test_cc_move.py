"""contact_control.move: the move's id, its end per axis, the outcomes callers wait for, the latch."""

from __future__ import annotations

from contact_control.axes import END_EXTERNAL_STOP, END_FT_VIOLATION, END_NONE
from contact_control.move import MoveState


def test_a_move_that_ends_on_an_axis_says_which_and_its_caller_hears_how():
    m = MoveState()
    assert not m.active and m.message == "no move yet"
    first = m.begin(True, t=1.0)
    assert m.active and m.t0 == 1.0 and m.outcome(first, still_running=True) is None
    m.finish(2, END_FT_VIOLATION, True, "axis z: limit", active=(0, 1, 2))
    assert m.end == [END_NONE, END_NONE, END_FT_VIOLATION, END_NONE, END_NONE, END_NONE]
    assert m.ended_axis == 2 and not m.active and m.message == "move ended: axis z: limit"
    assert m.outcome(first, still_running=True) is None  # a press still being released counts as running
    assert m.outcome(first, still_running=False) is True


def test_a_stop_ends_every_active_axis_and_fails_the_move():
    m = MoveState()
    move = m.begin(True, t=0.0)
    m.finish(-1, END_EXTERNAL_STOP, False, "stop requested", active=(0, 2))
    assert m.end == [END_EXTERNAL_STOP, END_NONE, END_EXTERNAL_STOP, END_NONE, END_NONE, END_NONE]
    assert m.ended_axis == -1 and m.outcome(move, still_running=False) is False


def test_a_request_without_laws_is_done_at_once_and_a_change_keeps_the_move_running():
    m = MoveState()
    empty = m.begin(False, t=0.0)
    assert not m.active and m.message == "no laws set" and m.outcome(empty, still_running=False) is True
    running = m.begin(True, t=0.0)
    m.finish(-1, END_EXTERNAL_STOP, False, "changed by a new request", active=(0,))
    changed = m.change()
    assert changed == running + 1 and m.active and m.message == "" and m.end == [END_NONE] * 6
    assert m.outcome(running, still_running=False) is False  # the old request's caller is answered


def test_the_latch_holds_until_unlatched_and_old_outcomes_are_forgotten():
    m = MoveState()
    m.latch("wrench over the global limit")
    assert m.latched and m.unlatch() and not m.latched and m.latch_message == ""
    assert not m.unlatch()
    ids = []
    for _ in range(70):
        ids.append(m.begin(True, t=0.0))
        m.finish(-1, END_EXTERNAL_STOP, True, "done", active=(0,))
    assert m.outcome(ids[-1], still_running=False) is True
    assert m.outcome(ids[0], still_running=False) is False  # forgotten: no longer kept for a caller
