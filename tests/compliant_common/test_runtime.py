"""tune_runtime's scheduler request: a short EEVDF slice for every thread, inherited by later threads."""

import json
import platform
import subprocess
import sys

import pytest

from compliant_common import runtime

# Run in a process of its own: the request applies to every thread of the process that makes it.
CHILD = """
import ctypes, json, platform, struct, threading
from compliant_common import runtime
attr = struct.Struct("IIQiIQQQII")
def slice_ns(tid=0):
    buf = ctypes.create_string_buffer(attr.size)
    nr = runtime._SYSCALLS[platform.machine()][1]
    assert ctypes.CDLL(None, use_errno=True).syscall(nr, tid, buf, attr.size, 0) == 0
    return attr.unpack(buf.raw)[5]
def in_thread(target):
    out = []
    thread = threading.Thread(target=lambda: out.append(target()))
    thread.start()
    thread.join()
    return out[0]
before = slice_ns()
parked = threading.Event()
waiting = threading.Thread(target=parked.wait)
waiting.start()
took = runtime.short_scheduler_slice(2e-4)
result = [before, took, slice_ns(), in_thread(slice_ns), slice_ns(waiting.native_id)]
parked.set()
waiting.join()
print(json.dumps(result))
"""


@pytest.mark.skipif(
    not sys.platform.startswith("linux") or platform.machine() not in runtime._SYSCALLS, reason="Linux only"
)
def test_short_slice_for_every_thread_and_inherited():
    out = subprocess.run([sys.executable, "-c", CHILD], capture_output=True, text=True, timeout=60,
                         check=True)
    before, took, after, later, parked = json.loads(out.stdout)
    if before == 0:  # a kernel without per-task slices (before EEVDF) reports none: nothing to ask for
        pytest.skip("the kernel has no per-task slice")
    assert took >= 2  # at least the main thread and the parked one
    assert after == later == parked == 200_000
