"""Every use of rospy's private internals in the stack, here and nowhere else (a test in tests/ greps src/
for them); tests/compliant_common/test_rospy_internals.py fails when rospy changes what they rely on.

* The clock, for a process that publishes /clock itself: its own rospy clock set by the publishing loop
  instead of by the /clock subscription rospy made for it (`drop_clock_subscription`, `set_rostime`).
* Whether rospy runs on the wall clock (`is_wallclock`: rospy.rostime's, marked "internal use"; the
  /use_sim_time parameter would say what the node was told, not what rospy does).
* Registering again with a restarted master (`registrations`, `node_uri`, `publisher_update`): rospy
  registers only at init and has no public re-registration; compliant_common.ros_master uses them.
* The stamp of a message received as `rospy.AnyMsg` (`header_stamp_ns`: its raw bytes are the private
  `_buff`): mujoco_driver's lockstep reads a controller's answers of any stamped type without deserialising.

The clock: private rospy, on purpose. Under /use_sim_time, `rospy.init_node` subscribes the process to
/clock, and rospy has no in-process delivery: every message the process publishes there would come back to
it over a loopback connection (one more subscriber to write to at every simulation step, 500-1000 Hz) and be
deserialised in a receive thread competing for the GIL, only to set a clock the loop already knows. rospy's
public API can neither drop that subscription (`init_node(disable_rostime=True)`, "for internal testing
only", leaves the process on the wall clock: its /rosout stamps, throttled logs and actionlib status would
leave simulated time) nor set the clock (only that subscription's callback does).
"""

from __future__ import annotations

import struct
from collections.abc import Callable

import rospy
import rospy.core
import rospy.impl.simtime as _simtime
from rospy.impl import registration
from rospy.rostime import _set_rostime, is_wallclock

__all__ = ["drop_clock_subscription", "header_stamp_ns", "is_wallclock", "node_uri", "publisher_update",
           "registrations", "set_rostime"]


def drop_clock_subscription() -> bool:
    """End the /clock subscription `rospy.init_node` made under /use_sim_time; True if there was one.

    This process's rospy clock then moves only by :func:`set_rostime`.
    """
    sub = getattr(_simtime, "_clock_sub", None)  # the name exists once init_simtime subscribed
    if sub is None:
        return False
    sub.unregister()
    _simtime._clock_sub = None
    return True


#: Set this process's rospy clock, as a /clock message would (it also wakes rospy sleeps). rospy keeps a copy
#: of the Time, so a caller may reuse its object; rospy's own function, so no call is added per message.
set_rostime: Callable[[rospy.Time], None] = _set_rostime


def node_uri() -> str:
    """This process's XML-RPC URI, as its registrations give it to the master."""
    return str(rospy.core.get_node_uri())


def registrations() -> tuple[list[list[str]], list[list[str]], list[list[str]]]:
    """This process's (publications, subscriptions, services): [name, type] pairs, [name, service URI] pairs,
    read under rospy's locks."""
    tm, sm = registration.get_topic_manager(), registration.get_service_manager()
    with tm.lock, sm.lock:
        return tm.get_publications(), tm.get_subscriptions(), sm.get_services()


def publisher_update(topic: str, publishers: list[str]) -> bool:
    """Connects this process's subscribers of `topic` to `publishers` (URIs), as rospy does when the master
    tells it of new publishers; False if rospy's registration manager is not there (no init_node)."""
    listeners = registration.get_registration_listeners()
    with listeners.lock:
        found = [item for item in listeners.listeners if isinstance(item, registration.RegManager)]
    if not found:
        return False
    found[0].publisher_update(topic, publishers)
    return True


_STAMP = struct.Struct("<II")  # a std_msgs/Header's stamp (secs, nsecs) after its uint32 seq


def header_stamp_ns(msg: rospy.AnyMsg) -> int | None:
    """The header stamp [ns] of a message received as `rospy.AnyMsg` whose type starts with a std_msgs/Header;
    None when it is too short to have one."""
    raw = msg._buff  # AnyMsg's raw bytes (see the module docstring)
    if len(raw) < 12:
        return None
    secs, nsecs = _STAMP.unpack_from(raw, 4)
    return int(secs) * 1_000_000_000 + int(nsecs)
