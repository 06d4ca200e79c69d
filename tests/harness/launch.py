"""Start real `roslaunch` / `rosrun` processes for a test and always stop them; one test's processes at a
time across the suite's workers (`process_slot`)."""

from __future__ import annotations

import contextlib
import fcntl
import os
import pathlib
import socket
import subprocess
import tempfile
import urllib.parse
import xmlrpc.client
from collections.abc import Iterator, Mapping, Sequence
from collections.abc import Set as AbstractSet

from harness.process import stop_process_group
from harness.waiting import wait_until

__all__ = ["Launched", "process_slot", "run_launch", "run_node"]

_SLOT = pathlib.Path(tempfile.gettempdir()) / "compliant_control_tests.slot"
_slots_held = 0  # re-entry count in this process


class _ExitedError(AssertionError):
    """The process died while waited for (its output is in the message already)."""


class Launched:
    """A launched process group with helpers to wait on what it should offer."""

    def __init__(self, proc: subprocess.Popen, log_path: str) -> None:
        self.proc = proc
        self._log_path = log_path

    def output(self) -> str:
        """Everything the process printed so far (stdout and stderr)."""
        with open(self._log_path, errors="replace") as log:
            return log.read()

    def warnings(self, last: int = 20) -> str:
        """The newest `last` lines the processes logged at WARN or above: why a run went wrong."""
        lines = [line for line in self.output().splitlines()
                 if any(level in line for level in ("[WARN]", "[ERROR]", "[FATAL]"))]
        return "\n".join(lines[-last:])

    def _master(self) -> xmlrpc.client.ServerProxy:
        return xmlrpc.client.ServerProxy(os.environ["ROS_MASTER_URI"])

    def _check_alive(self) -> None:
        if self.proc.poll() is not None:
            raise _ExitedError(f"process exited with {self.proc.returncode}:\n{self.output()[-4000:]}")

    def wait_for_topic(self, name: str, timeout: float = 20.0) -> None:
        """Waits until some node publishes `name`."""

        def published() -> bool:
            self._check_alive()
            _, _, topics = self._master().getPublishedTopics("/harness", "")
            return any(topic == name for topic, _ in topics)

        try:
            wait_until(published, timeout, f"topic {name} to be published")
        except _ExitedError:
            raise
        except AssertionError as err:  # the output when it failed, not when the wait began
            raise AssertionError(f"{err}\n{self.output()[-4000:]}") from None

    def wait_for_service(self, name: str, timeout: float = 20.0) -> None:
        """Waits until service `name` is registered with the master."""

        def registered() -> bool:
            self._check_alive()
            code, _, _ = self._master().lookupService("/harness", name)
            return code == 1

        try:
            wait_until(registered, timeout, f"service {name}")
        except _ExitedError:
            raise
        except AssertionError as err:  # the output when it failed, not when the wait began (empty then)
            raise AssertionError(f"{err}\n{self.output()[-4000:]}") from None

    def stop(self, timeout: float = 15.0) -> None:
        stop_process_group(self.proc, timeout)


@contextlib.contextmanager
def process_slot() -> Iterator[None]:
    """Holds the suite's one slot for started processes (a file lock, re-entrant within a process): two
    simulated stacks on a 2-core machine starve each other and a test then judges the load instead of the
    stack (docs/measurements.md, *Test suite*). The other worker goes on with tests that start nothing."""
    global _slots_held
    if _slots_held:
        _slots_held += 1
        try:
            yield
        finally:
            _slots_held -= 1
        return
    with open(_SLOT, "a") as slot:
        fcntl.flock(slot, fcntl.LOCK_EX)
        _slots_held = 1
        try:
            yield
        finally:
            _slots_held = 0
            fcntl.flock(slot, fcntl.LOCK_UN)


def _answers(api: str) -> bool:
    """Whether a node's XML-RPC API at `api` accepts a connection (a slow node answers late, still alive)."""
    try:
        parts = urllib.parse.urlsplit(api)
        with socket.create_connection((parts.hostname, parts.port), timeout=1.0):
            return True
    except ConnectionRefusedError:
        return False
    except (OSError, ValueError):
        return True  # unreachable for another reason: not known to be gone


@contextlib.contextmanager
def _spawn(cmd: Sequence[str], env: Mapping[str, str] | None) -> Iterator[Launched]:
    with process_slot(), _spawned(cmd, env) as launched:
        yield launched


@contextlib.contextmanager
def _spawned(cmd: Sequence[str], env: Mapping[str, str] | None) -> Iterator[Launched]:
    log = tempfile.NamedTemporaryFile(prefix="harness_", suffix=".log", delete=False)
    uri = dict(os.environ if env is None else env).get("ROS_MASTER_URI")
    _forget_dead_nodes(uri, check=True)
    before = _registered_nodes(_system_state(uri))
    proc = subprocess.Popen(
        list(cmd),
        env=dict(os.environ if env is None else env),
        stdin=subprocess.DEVNULL,
        stdout=log,
        stderr=subprocess.STDOUT,
        start_new_session=True,
    )
    launched = Launched(proc, log.name)
    try:
        yield launched
    finally:
        launched.stop()
        _forget_dead_nodes(uri, keep=before)
        log.close()
        os.unlink(log.name)


def _system_state(uri: str | None) -> list | None:
    """The master's getSystemState at `uri`; None without one (no master yet, or a test's fake one)."""
    if not uri:
        return None
    try:
        code, _msg, state = xmlrpc.client.ServerProxy(uri).getSystemState("/harness")
    except (OSError, xmlrpc.client.Error):
        return None
    return state if code == 1 else None


def _registered_nodes(state: list | None) -> set[str]:
    """Every node `state` (getSystemState) has a publisher, subscriber or service of."""
    return {node for kind in state or () for _name, nodes in kind for node in nodes}


def _forget_dead_nodes(uri: str | None, keep: AbstractSet[str] = frozenset(), check: bool = False) -> None:
    """Unregisters what every node but those in `keep` left with the master (`rosnode cleanup`); `check`:
    only the nodes whose API refuses a connection (gone). A node killed before it unregistered (SIGKILL after
    the stop timeout) stays registered under its name and API; when the next test's node of that name
    registers, the master sends "new node registered with same name" to the old API, and a new node that got
    the same port from the OS is the one shut down (a panda replay test's named_poses died that way:
    control_stack's stale API was its port; named_poses' FollowJointTrajectory tests lost theirs the same way
    to a stale node from before their launch): so before each launch, every node that no longer answers is
    forgotten too."""
    state = _system_state(uri)
    if state is None or uri is None:
        return
    master = xmlrpc.client.ServerProxy(uri)
    publishers, subscribers, services = state
    for node in _registered_nodes(state) - keep:
        code, _msg, api = master.lookupNode("/harness", node)
        if code != 1 or (check and _answers(api)):
            continue
        for topic, nodes in publishers:
            if node in nodes:
                master.unregisterPublisher(node, topic, api)
        for topic, nodes in subscribers:
            if node in nodes:
                master.unregisterSubscriber(node, topic, api)
        for service, nodes in services:
            if node in nodes:
                code, _msg, service_api = master.lookupService("/harness", service)
                if code == 1:
                    master.unregisterService(node, service, service_api)


@contextlib.contextmanager
def run_launch(
    package: str,
    launch_file: str,
    args: Mapping[str, object] | None = None,
    env: Mapping[str, str] | None = None,
) -> Iterator[Launched]:
    """Runs `roslaunch package launch_file key:=value ...` against the session's master."""
    cmd = ["roslaunch", "--wait", package, launch_file]
    cmd += [f"{key}:={value}" for key, value in (args or {}).items()]
    with _spawn(cmd, env) as launched:
        yield launched


@contextlib.contextmanager
def run_node(
    package: str,
    executable: str,
    args: Sequence[str] = (),
    params: Mapping[str, object] | None = None,
    name: str | None = None,
    env: Mapping[str, str] | None = None,
) -> Iterator[Launched]:
    """Runs `rosrun package executable args` with private params given as `_key:=value`."""
    cmd = ["rosrun", package, executable, *args]
    if name:
        cmd.append(f"__name:={name}")
    for key, value in (params or {}).items():
        cmd.append(f"_{key.lstrip('~_')}:={value}")
    with _spawn(cmd, env) as launched:
        yield launched
