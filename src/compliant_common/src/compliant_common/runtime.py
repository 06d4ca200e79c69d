"""Interpreter and scheduler tuning for processes with control threads; one place for every node."""

from __future__ import annotations

import ctypes
import gc
import os
import platform
import struct
import sys

__all__ = ["LATENCY_SLICE", "short_scheduler_slice", "tune_runtime"]

#: [s] Scheduler slice asked for every thread of a control process (Linux's minimum, 0.1 ms).
LATENCY_SLICE = 1e-4

# sched_setattr / sched_getattr: not in Python's os module. Numbers per architecture (asm-generic for arm64).
_SYSCALLS = {"x86_64": (314, 315), "aarch64": (274, 275)}
_SCHED_OTHER = 0
_ATTR = struct.Struct("IIQiIQQQII")  # struct sched_attr, version 1 (56 bytes)


def tune_runtime(period: float, switch_fraction: float = 0.1) -> None:
    """Keeps the interpreter and the kernel from delaying a control thread with period `period` [s]; call
    once, after start-up. The switch interval becomes at most `switch_fraction` of the period.

    A thread waiting for the GIL can wait a whole switch interval (5 ms by default) for a busy one (rospy's
    receive threads at 1 kHz): keep it well below the period so a message is handled on arrival. Start-up
    objects (models, rospy machinery) never die; a full collection over them stalls a cycle for ~15 ms, so
    they are frozen out of it. Every thread asks the kernel for a short slice (`short_scheduler_slice`).
    """
    sys.setswitchinterval(min(sys.getswitchinterval(), period * switch_fraction))
    gc.collect()
    gc.freeze()
    short_scheduler_slice()


def short_scheduler_slice(slice_s: float = LATENCY_SLICE) -> int:
    """Asks Linux's EEVDF scheduler (6.6 and later) for a `slice_s` slice for every thread of this process
    (threads and processes started later inherit it); returns how many threads took it (0 where unsupported).

    On a busy machine a woken thread runs when it is the eligible task with the earliest virtual deadline,
    its eligible time plus its slice (1.4 ms by default on this 2-core VM); since 6.12 a task with a shorter
    slice may also preempt the running one when it wakes. A short slice so brings a 2 ms control cycle's
    thread onto a CPU soon after its timer or message wakes it, ahead of batch work with default slices. Its
    share of the CPU (weight, nice value) is unchanged, and no privilege is needed. Threads not of the
    normal policy (real-time, batch, idle) are left alone; kernels without custom slices ignore the request.
    """
    numbers = _SYSCALLS.get(platform.machine())
    if numbers is None or not sys.platform.startswith("linux"):
        return 0
    setattr_nr, getattr_nr = numbers
    try:
        libc = ctypes.CDLL(None, use_errno=True)
        tids = [int(tid) for tid in os.listdir("/proc/self/task")]
    except OSError:
        return 0
    runtime = max(1, round(slice_s * 1e9))
    done = 0
    for tid in tids:
        buf = ctypes.create_string_buffer(_ATTR.size)
        if libc.syscall(getattr_nr, tid, buf, _ATTR.size, 0) != 0:
            continue  # the thread ended, or no sched_getattr
        _size, policy, _flags, nice, priority, *_ = _ATTR.unpack(buf.raw)
        if policy != _SCHED_OTHER:
            continue
        attr = _ATTR.pack(_ATTR.size, policy, 0, nice, priority, runtime, 0, 0, 0, 0)
        if libc.syscall(setattr_nr, tid, ctypes.c_char_p(attr), 0) == 0:
            done += 1
    return done
