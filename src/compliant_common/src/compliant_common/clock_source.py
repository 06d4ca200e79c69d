"""For a process that publishes /clock itself: its own rospy clock set by the publishing loop instead of by
the /clock subscription rospy made for it.

Private rospy, on purpose. Under /use_sim_time, `rospy.init_node` subscribes the process to /clock, and
rospy has no in-process delivery: every message the process publishes there would come back to it over a
loopback connection (one more subscriber to write to at every simulation step, 500-1000 Hz) and be
deserialised in a receive thread competing for the GIL, only to set a clock the loop already knows. rospy's
public API can neither drop that subscription (`init_node(disable_rostime=True)`, "for internal testing
only", leaves the process on the wall clock: its /rosout stamps, throttled logs and actionlib status would
leave simulated time) nor set the clock (only that subscription's callback does).
tests/compliant_common/test_clock_source.py fails when rospy changes what this relies on.
"""

from __future__ import annotations

from collections.abc import Callable

import rospy
import rospy.impl.simtime as _simtime
from rospy.rostime import _set_rostime

__all__ = ["drop_clock_subscription", "set_rostime"]


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
