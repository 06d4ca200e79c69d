"""ClockWatch: which clock readings count as a jump (back, forward) or a stopped clock."""

import types

import pytest
from compliant_common.clock import ClockWatch

from compliant_common import ros_time


def feed(watch: ClockWatch, readings):
    """(ros, monotonic) pairs -> the jumps reported, in order."""
    return [j for j in (watch.observe(ros, mono) for ros, mono in readings) if j is not None]


def test_a_steady_clock_never_jumps_even_with_stalls_and_a_fast_simulation():
    watch = ClockWatch(forward_tolerance=1.0, stop_tolerance=0.5)
    steady = [(100.0 + 0.002 * k, 5.0 + 0.002 * k) for k in range(1000)]
    stall = [(102.5, 7.5), (103.3, 8.3)]  # a 0.8 s VM stall moves both clocks alike
    fast = [(103.3 + 0.02 * k, 8.3 + 0.002 * k) for k in range(1, 100)]  # 10x real time
    assert feed(watch, steady + stall + fast) == []


def test_back_and_forward_jumps_are_reported_once_each_with_their_size():
    watch = ClockWatch(forward_tolerance=1.0)
    jumps = feed(watch, [(50.0, 1.0), (50.002, 1.002), (40.0, 1.004), (40.002, 1.006), (60.0, 1.008)])
    assert [round(j.size, 2) for j in jumps] == [-10.0, 20.0]
    assert jumps[0].backwards and not jumps[1].backwards
    assert "back by 10.002 s" in jumps[0].describe()
    assert "forward" in jumps[1].describe()
    assert watch.jumps == 2


def test_a_reading_taken_earlier_by_another_thread_is_not_a_jump():
    watch = ClockWatch()
    assert watch.observe(10.0, 1.0) is None
    assert watch.observe(10.5, 1.5) is None
    assert watch.observe(10.2, 1.2) is None  # read before the previous one, reported after it


def test_a_stopped_clock_is_reported_once_then_again_after_it_ran_and_stopped_again():
    watch = ClockWatch(stop_tolerance=0.5)
    frozen = [(7.0, 1.0 + 0.1 * k) for k in range(10)]
    jumps = feed(watch, frozen)
    assert len(jumps) == 1 and jumps[0].stopped and "stopped" in jumps[0].describe()
    assert feed(watch, [(7.1, 2.1)]) == []  # running again
    assert len(feed(watch, [(7.1, 2.2 + 0.1 * k) for k in range(10)])) == 1
    assert feed(ClockWatch(), frozen) == []  # not watched by default


def test_bad_tolerances_are_refused():
    with pytest.raises(ValueError):
        ClockWatch(forward_tolerance=0.0)


def test_jump_aware_clock_does_not_judge_a_reading_held_up_between_its_clocks(monkeypatch):
    """A thread preempted between reading the ROS clock and the monotonic one must not report a jump back."""
    readings = iter([
        10.0000, 100.000, 10.0001,  # monotonic, ROS time, monotonic: a prompt reading
        10.0020, 100.002, 10.0021,
        10.0030, 99.9990, 10.0080,  # held up 5 ms between the reads: an old ROS time, not judged
        10.0090, 100.009, 10.0091,
        10.0100, 99.0000, 10.0101,  # a real step back by 1 s, read promptly: reported
    ])
    fake = types.SimpleNamespace(monotonic=lambda: next(readings), time=lambda: next(readings))
    monkeypatch.setattr(ros_time, "time", fake)
    monkeypatch.setattr(ros_time, "is_wallclock", lambda: True)
    clock = ros_time.JumpAwareClock()
    results = [clock.read() for _ in range(5)]
    assert [t for t, _ in results] == [100.000, 100.002, 99.999, 100.009, 99.0]
    assert [jump is None for _, jump in results] == [True, True, True, True, False]
    assert results[4][1].backwards
