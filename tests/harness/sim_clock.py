"""The test process on the simulation's clock while a stack runs on it (`sim_time:=true`).

The session's client node starts on the wall clock (one rospy node per process). A stack launched with
`sim_time:=true` publishes /clock; inside `sim_clock()` this process's rospy time follows it, so a client
(the demonstration runner, a test's waits) measures the simulation's seconds however fast it runs; on exit the
wall clock comes back and /use_sim_time is deleted (the launch's nodes have read it already).
"""

from __future__ import annotations

import contextlib
from collections.abc import Iterator

#: The real-time factor of the simulated stacks the e2e tests launch on simulated time: as fast as this where
#: the machine allows; a busier machine slows the simulation instead of thinning its states or letting a
#: driven arm run ahead of its controller (mujoco_driver README, *How it runs*); tests judge simulated time.
FAST = 2.0


def fast_args(**args: object) -> dict[str, object]:
    """A sim launch's arguments for simulated time at FAST, with `args` on top."""
    return {"sim_time": "true", "real_time_factor": FAST, **args}


@contextlib.contextmanager
def sim_clock(timeout: float = 60.0) -> Iterator[None]:
    """This process's rospy clock follows /clock until the block ends; waits up to `timeout` s (wall) for
    the first tick."""
    import threading

    import rospy
    import rospy.rostime
    from compliant_common.rospy_internals import set_rostime
    from rosgraph_msgs.msg import Clock

    ticked = threading.Event()

    def on_clock(msg: Clock) -> None:
        set_rostime(msg.clock)
        ticked.set()

    sub = rospy.Subscriber("/clock", Clock, on_clock, queue_size=1, tcp_nodelay=True)
    try:
        if not ticked.wait(timeout):
            raise AssertionError(f"no /clock within {timeout} s: was the stack launched with sim_time:=true?")
        yield
    finally:
        sub.unregister()
        rospy.rostime.switch_to_wallclock()
        # The launch set /use_sim_time true on the session's master; a node of a later test would read it at
        # its start and wait for a /clock that no longer comes.
        if rospy.has_param("/use_sim_time"):
            rospy.delete_param("/use_sim_time")
