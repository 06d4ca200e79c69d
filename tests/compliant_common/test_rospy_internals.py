"""rospy_internals relies on private rospy (see the module for why): these fail when rospy changes what it
relies on, i.e. where init_node keeps its /clock subscription and what setting the clock does. No master:
rospy's time globals are put back after each test."""

import threading

import pytest
import rospy
import rospy.client
import rospy.impl.simtime as simtime
import rospy.rostime
import rospy.topics
from rosgraph_msgs.msg import Clock

from compliant_common import rospy_internals


@pytest.fixture
def rospy_time(monkeypatch: pytest.MonkeyPatch) -> None:
    """rospy's clock initialised and on the wall clock, as after init_node without /use_sim_time."""
    monkeypatch.setattr(rospy.rostime, "_rostime_initialized", True)
    monkeypatch.setattr(rospy.rostime, "_rostime_current", None)


class _Subscriber:
    def __init__(self, topic: str, data_class: type, callback, queue_size: int | None = None) -> None:
        self.topic, self.data_class, self.callback = topic, data_class, callback
        self.unregistered = False

    def unregister(self) -> None:
        self.unregistered = True


def test_the_clock_subscription_init_node_makes_under_sim_time_is_the_one_dropped(monkeypatch, rospy_time):
    assert "init_simtime" in rospy.client.init_node.__code__.co_names  # init_node makes it with this
    made: list[_Subscriber] = []

    def subscribe(*args, **kwargs) -> _Subscriber:
        made.append(_Subscriber(*args, **kwargs))
        return made[-1]

    monkeypatch.setattr(rospy.topics, "Subscriber", subscribe)
    monkeypatch.setattr(simtime, "_is_use_simtime", lambda: True)
    monkeypatch.setattr(simtime, "_clock_sub", None, raising=False)
    assert rospy_internals.drop_clock_subscription() is False  # none yet
    assert simtime.init_simtime()
    [sub] = made
    assert (sub.topic, sub.data_class) == ("/clock", Clock)
    sub.callback(Clock(rospy.Time(7, 5)))  # that subscription is what moves this process's clock
    assert rospy.Time.now() == rospy.Time(7, 5)
    assert rospy_internals.drop_clock_subscription() is True
    assert sub.unregistered and rospy_internals.drop_clock_subscription() is False


def test_set_rostime_moves_this_process_clock_to_a_copy_and_wakes_sleepers(rospy_time):
    stamp = rospy.Time(12, 500)
    rospy_internals.set_rostime(stamp)
    assert not rospy.rostime.is_wallclock() and rospy.Time.now() == rospy.Time(12, 500)
    stamp.secs = 99  # the node fills its one stamp object in place at every step
    assert rospy.get_time() == pytest.approx(12.0000005)
    cond = rospy.rostime.get_rostime_cond()  # what rospy.sleep and rospy.Rate wait on under sim time
    with cond:
        setter = threading.Thread(target=rospy_internals.set_rostime, args=(rospy.Time(13),))
        setter.start()
        assert cond.wait(timeout=5.0), "setting the clock did not wake a waiting rospy.sleep"
    setter.join()
    assert rospy.get_time() == 13.0


def test_the_registration_internals_master_watch_uses_are_there():
    """What compliant_common.ros_master re-registers with after a master restart (its behaviour end to end:
    tests/robot_packages/test_robot_faults.py restarts roscore under the running stack)."""
    from rospy.impl import registration

    publications, subscriptions, services = rospy_internals.registrations()
    assert all(isinstance(x, list) for x in (publications, subscriptions, services))
    assert callable(rospy.core.get_node_uri)
    assert callable(getattr(registration.RegManager, "publisher_update", None))
    assert rospy_internals.publisher_update("/nobody", []) in (True, False)


def test_no_other_module_in_src_touches_rospy_internals():
    """The one place: anything private of rospy elsewhere is a bug waiting for a rospy update."""
    import pathlib
    import re

    src = pathlib.Path(__file__).resolve().parents[2] / "src"
    private = re.compile(r"rospy\.impl|rospy\.core\.|rospy\.rostime|_connection_header|_set_rostime|"
                         r"from rospy\.\w+ import|import rospy\.\w+")
    allowed = src / "compliant_common" / "src" / "compliant_common" / "rospy_internals.py"
    found = [f"{path.relative_to(src)}:{n}: {line.strip()}"
             for path in src.glob("*/src/**/*.py") if path != allowed
             for n, line in enumerate(path.read_text().splitlines(), 1) if private.search(line)]
    assert found == [], "\n".join(found)


def test_header_stamp_ns_reads_the_stamp_of_a_raw_stamped_message_and_refuses_a_short_one():
    import io

    from geometry_msgs.msg import WrenchStamped

    msg = WrenchStamped()
    msg.header.seq, msg.header.stamp = 7, rospy.Time(12, 345)
    buff = io.BytesIO()
    msg.serialize(buff)
    raw = rospy.AnyMsg()
    raw.deserialize(buff.getvalue())
    assert rospy_internals.header_stamp_ns(raw) == 12_000_000_345
    short = rospy.AnyMsg()
    short.deserialize(b"\x00" * 8)
    assert rospy_internals.header_stamp_ns(short) is None
