"""Interpreter tuning for processes with control threads; one place for every node."""

from __future__ import annotations

import gc
import sys

__all__ = ["tune_runtime"]


def tune_runtime(period: float, switch_fraction: float = 0.1) -> None:
    """Keeps the interpreter from delaying a control thread with period `period` [s]; call once, after
    start-up. The switch interval becomes at most `switch_fraction` of the period.

    A thread waiting for the GIL can wait a whole switch interval (5 ms by default) for a busy one (rospy's
    receive threads at 1 kHz): keep it well below the period so a message is handled on arrival. Start-up
    objects (models, rospy machinery) never die; a full collection over them stalls a cycle for ~15 ms, so
    they are frozen out of it.
    """
    sys.setswitchinterval(min(sys.getswitchinterval(), period * switch_fraction))
    gc.collect()
    gc.freeze()
