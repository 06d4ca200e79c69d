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
    """Sends SIGINT to `proc`'s process group, then SIGKILL if it is still running after `timeout` s; then
    SIGKILL to every process that was below it and still runs. roslaunch starts each node in a session of its
    own (setsid), so a group signal misses the nodes: a roslaunch killed after the timeout left them running,
    still registered with the master, and a later node of the same name was shut down in their place."""
    if proc.poll() is not None:
        return
    below = _descendants(proc.pid)
    with contextlib.suppress(ProcessLookupError):
        os.killpg(proc.pid, signal.SIGINT)
    try:
        proc.wait(timeout=timeout)
    except subprocess.TimeoutExpired:
        with contextlib.suppress(ProcessLookupError):
            os.killpg(proc.pid, signal.SIGKILL)
        proc.wait()
    left = [p for p in below if _started(p[0]) == p[1]]
    for pid, _ in left:
        with contextlib.suppress(ProcessLookupError):
            os.kill(pid, signal.SIGKILL)
    deadline = time.monotonic() + 10.0
    while any(_started(pid) == start for pid, start in left) and time.monotonic() < deadline:
        time.sleep(0.01)


def _stat(pid: int | str) -> list[str] | None:
    """The fields of /proc/<pid>/stat after the command's name (state first), None if it is gone."""
    try:
        with open(f"/proc/{pid}/stat", encoding="ascii", errors="replace") as handle:
            return handle.read().rsplit(")", 1)[1].split()
    except (OSError, IndexError):
        return None


def _started(pid: int) -> str | None:
    """The start time of a running process `pid` (None once it is gone or a zombie): told apart from a later
    process given the same pid."""
    fields = _stat(pid)
    return None if fields is None or fields[0] in ("Z", "X") else fields[19]


def _descendants(pid: int) -> list[tuple[int, str]]:
    """(pid, start time) of every process below `pid`."""
    children: dict[int, list[int]] = {}
    for entry in os.listdir("/proc"):
        fields = _stat(entry) if entry.isdigit() else None
        if fields is not None:
            children.setdefault(int(fields[1]), []).append(int(entry))
    found, todo = [], [pid]
    while todo:
        for child in children.get(todo.pop(), []):
            start = _started(child)
            if start is not None:
                found.append((child, start))
            todo.append(child)
    return found


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
