"""A second computer for a test: a Linux network namespace joined to this one by a veth pair, each end with an
address of the test's own (10.231.N.1 here, 10.231.N.2 there). Processes started with `Link.run_there` see
only that namespace's network: they reach this side over the veth, as a robot's computer reaches the control
computer over Ethernet. Needs root (CI runs as root)."""

from __future__ import annotations

import contextlib
import os
import shutil
import subprocess
from collections.abc import Iterator, Sequence
from dataclasses import dataclass

__all__ = ["Link", "can_make_links", "second_computer"]


@dataclass(frozen=True)
class Link:
    namespace: str  # the other computer's network namespace
    device: str  # this side's end of the veth pair
    here: str  # this side's address
    there: str  # the other side's address

    def run_there(self, command: Sequence[str], **popen) -> subprocess.Popen:
        """Starts `command` in the other namespace (its own process group, stopped with
        harness.process.stop_process_group)."""
        return subprocess.Popen(["ip", "netns", "exec", self.namespace, *command], start_new_session=True,
                                **popen)

    def bytes_received(self) -> int:
        """Bytes this side's end has received from the other computer."""
        with open(f"/sys/class/net/{self.device}/statistics/rx_bytes") as counter:
            return int(counter.read())


def can_make_links() -> str:
    """'' when this process may create network namespaces, else why not."""
    if os.geteuid() != 0:
        return "network namespaces need root"
    if shutil.which("ip") is None:
        return "iproute2's `ip` is not installed"
    return ""


def _ip(*args: str, namespace: str = "") -> None:
    command = ["ip", *(["netns", "exec", namespace, "ip"] if namespace else []), *args]
    subprocess.run(command, check=True, capture_output=True, text=True)


@contextlib.contextmanager
def second_computer() -> Iterator[Link]:
    """A namespace and a veth pair named and addressed after this process (two workers never collide),
    removed afterwards even on an error."""
    tag = os.getpid() % 250 + 1
    link = Link(f"cc_test_{os.getpid()}", f"ccv{os.getpid()}", f"10.231.{tag}.1", f"10.231.{tag}.2")
    peer = f"ccp{os.getpid()}"
    _ip("netns", "add", link.namespace)
    try:
        _ip("link", "add", link.device, "type", "veth", "peer", "name", peer)
        _ip("link", "set", peer, "netns", link.namespace)
        _ip("addr", "add", f"{link.here}/30", "dev", link.device)
        _ip("link", "set", link.device, "up")
        _ip("addr", "add", f"{link.there}/30", "dev", peer, namespace=link.namespace)
        _ip("link", "set", peer, "up", namespace=link.namespace)
        _ip("link", "set", "lo", "up", namespace=link.namespace)
        yield link
    finally:
        with contextlib.suppress(subprocess.CalledProcessError):
            _ip("link", "del", link.device)  # takes its peer with it
        _ip("netns", "del", link.namespace)
