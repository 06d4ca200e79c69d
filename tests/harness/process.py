"""Processes of a test: stopping a group the way roslaunch users do (SIGINT, then SIGKILL after a grace
period), finding a ROS node's process, stalling one (SIGSTOP ... SIGCONT) as a busy machine does."""

from __future__ import annotations

import contextlib
import os
import signal
import subprocess
import time
import xmlrpc.client
from collections.abc import Iterator

__all__ = ["node_pid", "stalled", "stop_process_group"]


def stop_process_group(proc: subprocess.Popen, timeout: float = 10.0) -> None:
    """Sends SIGINT to `proc`'s process group, then SIGKILL if it is still running after `timeout` s."""
    if proc.poll() is not None:
        return
    with contextlib.suppress(ProcessLookupError):
        os.killpg(proc.pid, signal.SIGINT)
    try:
        proc.wait(timeout=timeout)
    except subprocess.TimeoutExpired:
        with contextlib.suppress(ProcessLookupError):
            os.killpg(proc.pid, signal.SIGKILL)
        proc.wait()


def node_pid(name: str) -> int:
    """The process id of the ROS node `name` (its slave API's getPid)."""
    master = xmlrpc.client.ServerProxy(os.environ["ROS_MASTER_URI"])
    code, message, uri = master.lookupNode("/pytest_probe", name)
    assert code == 1, f"{name}: {message}"
    return int(xmlrpc.client.ServerProxy(uri).getPid("/pytest_probe")[2])


@contextlib.contextmanager
def stalled(pid: int) -> Iterator[float]:
    """The process is stopped (SIGSTOP) inside the block and continued after it, even on an error; yields the
    monotonic time it stopped."""
    os.kill(pid, signal.SIGSTOP)
    try:
        yield time.monotonic()
    finally:
        with contextlib.suppress(ProcessLookupError):
            os.kill(pid, signal.SIGCONT)
