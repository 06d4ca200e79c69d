"""A private ROS master for tests: a real roscore on a free loopback port."""

from __future__ import annotations

import os
import socket
import subprocess
import time
import xmlrpc.client

from harness.process import stop_process_group

__all__ = ["Master", "free_port", "restart_master", "start_master"]

DEFAULT_PORT = 11311


def free_port() -> int:
    """Returns a free TCP port on loopback, never ROS's default 11311."""
    while True:
        with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as sock:
            sock.bind(("127.0.0.1", 0))
            port = sock.getsockname()[1]
        if port != DEFAULT_PORT:
            return port


class Master:
    """A running roscore and the environment that points clients at it."""

    def __init__(self, port: int, proc: subprocess.Popen, env: dict[str, str]) -> None:
        self.port = port
        self.proc = proc
        self.env = env
        self.uri = env["ROS_MASTER_URI"]

    def is_up(self) -> bool:
        try:
            code, _, _ = xmlrpc.client.ServerProxy(self.uri).getSystemState("/probe")
        except OSError:
            return False
        return code == 1

    def stop(self) -> None:
        stop_process_group(self.proc)


def master_env(port: int, base: dict[str, str] | None = None) -> dict[str, str]:
    """Environment for a master on `port` whose traffic stays on loopback."""
    env = dict(os.environ if base is None else base)
    env["ROS_MASTER_URI"] = f"http://127.0.0.1:{port}"
    env["ROS_HOSTNAME"] = "127.0.0.1"
    env.pop("ROS_IP", None)
    return env


def start_master(timeout: float = 30.0, log_dir: str | None = None, port: int | None = None) -> Master:
    """Starts `roscore -p PORT` (a free port unless given) in its own process group and waits until it
    answers.

    Raises:
        RuntimeError: roscore exited or did not answer within `timeout`.
    """
    port = free_port() if port is None else port
    env = master_env(port)
    if log_dir:
        env["ROS_LOG_DIR"] = log_dir
    proc = subprocess.Popen(
        ["roscore", "-p", str(port)],
        env=env,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
        start_new_session=True,
    )
    master = Master(port, proc, env)
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        if proc.poll() is not None:
            raise RuntimeError(f"roscore on port {port} exited with code {proc.returncode}")
        if master.is_up() and _rosout_up(master):
            return master
        time.sleep(0.05)
    master.stop()
    raise RuntimeError(f"roscore on port {port} did not come up within {timeout} s")


def restart_master(master: Master, down_for: float = 0.0, timeout: float = 30.0) -> float:
    """Stops `master` (as a crash or Ctrl-C would), waits `down_for` s and starts a new, empty roscore on the
    same port; `master` then refers to the new one. Returns the monotonic time the old one was stopped.
    """
    master.stop()
    stopped = time.monotonic()
    time.sleep(down_for)  # the outage itself is what a restart test simulates
    new = start_master(timeout, master.env.get("ROS_LOG_DIR"), master.port)
    master.proc = new.proc
    return stopped


def _rosout_up(master: Master) -> bool:
    code, _, state = xmlrpc.client.ServerProxy(master.uri).getSystemState("/probe")
    return code == 1 and any(name == "/rosout" for name, _ in state[0] + state[1])
