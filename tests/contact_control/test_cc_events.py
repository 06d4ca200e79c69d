"""Contact events from cycle results (contact_control.events): touch and release with hysteresis, a force
limit that ends a move, the global limit, and moves that end or are replaced."""

from __future__ import annotations

from contact_control.events import FORCE_LIMIT, MOVE_ENDED, RELEASE, TOUCH, EventWatch
from contact_control.laws import AxisLaw
from contact_control.stage import ContactStage

from contact_control import load_settings

from .cc_sim import DT, controller, laws

IDENTITY = [[1.0, 0, 0, 0], [0, 1.0, 0, 0], [0, 0, 1.0, 0], [0, 0, 0, 1.0]]


def kinds(watch: EventWatch) -> list[int]:
    out = [e.kind for e in watch.pending]
    watch.pending.clear()
    return out


def test_touch_and_release_fire_once_each_with_hysteresis():
    ctrl = controller(lp_filter_enabled=False)
    watch = EventWatch(3.0, 1.5)
    t = 0.0
    for fz in [0.0, 1.0, 2.9, 3.2, 4.0, 2.0, 1.6, 3.5, 1.4, 0.0, 0.5]:
        t += DT
        watch.observe(ctrl.update((0, 0, fz, 0, 0, 0), t), ctrl.end_message)
        if fz == 3.2:
            assert kinds(watch) == [TOUCH]
        elif fz == 1.4:
            assert kinds(watch) == [RELEASE]
        else:
            assert kinds(watch) == [], fz  # 3.5 after 1.6 is the same touch: no release came between


def test_a_move_ended_on_its_force_limit_reports_force_limit_then_move_ended_with_the_reason():
    ctrl = controller(lp_filter_enabled=False, force_limit_samples=1, force_limit_arm_time=0.0)
    watch = EventWatch(3.0, 1.5)
    move = ctrl.set_laws(laws(z=AxisLaw(1, damping=30.0, force_limit=8.0)), None, 0.0)
    events = []
    for i, fz in enumerate([0.0, 5.0, 9.0, 9.0]):
        watch.observe(ctrl.update((0, 0, fz, 0, 0, 0), (i + 1) * DT), ctrl.end_message)
        events += watch.pending
        watch.pending.clear()
    assert [e.kind for e in events] == [TOUCH, FORCE_LIMIT, MOVE_ENDED]
    limit, ended = events[1], events[2]
    assert limit.move_id == ended.move_id == move
    assert "force/torque limit" in ended.message and limit.wrench[2] == 9.0


def test_the_global_limit_and_a_replaced_move_are_events_too():
    ctrl = controller(lp_filter_enabled=False, force_limit_samples=1)
    watch = EventWatch(3.0, 1.5)
    first = ctrl.set_laws(laws(z=AxisLaw(1, damping=30.0)), None, 0.0)
    watch.observe(ctrl.update((0, 0, 0, 0, 0, 0), DT), ctrl.end_message)
    ctrl.set_laws(laws(x=AxisLaw(1, damping=30.0)), None, 2 * DT)  # another law type: a new move
    watch.observe(ctrl.update((0, 0, 0, 0, 0, 0), 3 * DT), ctrl.end_message)
    ended = watch.pending[-1]
    assert ended.kind == MOVE_ENDED and ended.move_id == first and "replaced" in ended.message
    watch.pending.clear()
    watch.observe(ctrl.update((0, 0, 40.0, 0, 0, 0), 4 * DT), ctrl.end_message)
    # From no contact straight over the global limit (a stiff surface met fast, a stalled cycle): the contact
    # still begins with a touch, so a task waiting for one sees it.
    assert kinds(watch) == [TOUCH, FORCE_LIMIT, MOVE_ENDED]
    watch.observe(ctrl.update((0, 0, 40.0, 0, 0, 0), 5 * DT), ctrl.end_message)
    assert kinds(watch) == []  # latched: once


def test_the_stage_drains_events_with_the_end_effector_pose():
    stage = ContactStage(load_settings({"tare_on_startup": False, "lp_filter_enabled": False}),
                         lambda frame: [row[:] for row in IDENTITY])
    stage.on_wrench((0, 0, 0, 0, 0, 0), "", None, DT)
    stage.on_wrench((0, 0, 6.0, 0, 0, 0), "", None, 2 * DT)
    (event,) = stage.events
    assert event.kind == TOUCH and event.pose is not None and event.pose[2][3] == 0.0
