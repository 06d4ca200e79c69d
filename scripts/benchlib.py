"""Helpers the benchmark scripts share: percentiles, CPU time and steal, free ports, stopping processes."""

from __future__ import annotations

import contextlib
import os
import pathlib
import signal
import socket
import statistics
import subprocess

__all__ = ["cpu_seconds", "free_port", "pct", "percentiles", "steal_ticks", "stop_processes"]


def percentiles(samples_s: list[float]) -> tuple[float, float]:
    """(median, p99) in microseconds of samples in seconds."""
    ordered = sorted(samples_s)
    return statistics.median(ordered) * 1e6, ordered[min(len(ordered) - 1, int(0.99 * len(ordered)))] * 1e6


def pct(samples: list[float], q: float) -> float:
    """The q-th percentile (0-100) of `samples`, NaN if empty."""
    ordered = sorted(samples)
    return ordered[min(len(ordered) - 1, int(q / 100.0 * len(ordered)))] if ordered else float("nan")


def cpu_seconds(pid: int) -> float:
    """User + system CPU time of a process (Linux /proc)."""
    fields = pathlib.Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")


def steal_ticks() -> int:
    """Clock ticks all CPUs waited for the hypervisor (/proc/stat), a measure of the host's noise."""
    with open("/proc/stat") as stat:
        return int(stat.readline().split()[8])


def free_port() -> int:
    """A free TCP port on loopback (never ROS's default 11311)."""
    while True:
        with socket.socket() as sock:
            sock.bind(("127.0.0.1", 0))
            port = sock.getsockname()[1]
        if port != 11311:
            return port


def stop_processes(procs: list[subprocess.Popen]) -> None:
    """SIGINT each process group we started (by its id), then SIGKILL what is left after 10 s."""
    for proc in procs:
        with contextlib.suppress(ProcessLookupError):
            os.killpg(proc.pid, signal.SIGINT)
    for proc in procs:
        try:
            proc.wait(timeout=10)
        except subprocess.TimeoutExpired:
            with contextlib.suppress(ProcessLookupError):
                os.killpg(proc.pid, signal.SIGKILL)
            proc.wait()
