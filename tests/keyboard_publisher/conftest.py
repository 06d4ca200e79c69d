"""A process on a real pseudo-terminal, for running key_to_twist (and roslaunch) as a user would."""

from __future__ import annotations

import contextlib
import os
import select
import subprocess
import termios
import threading
from collections.abc import Iterator, Sequence

import pytest
from harness.process import stop_process_group
from harness.waiting import wait_until


class PtyProcess:
    """`cmd` with a fresh pty as stdin, stdout and stderr; the test holds the master side.

    The slave side stays open here too, so the terminal's mode can be read after the child exits.
    """

    def __init__(self, cmd: Sequence[str]) -> None:
        self.master, self.slave = os.openpty()
        self.initial_mode = termios.tcgetattr(self.slave)
        self.proc = subprocess.Popen(
            list(cmd),
            stdin=self.slave,
            stdout=self.slave,
            stderr=self.slave,
            env=dict(os.environ),
            start_new_session=True,
        )
        self._chunks: list[bytes] = []
        self._lock = threading.Lock()
        self._done = threading.Event()
        self._thread = threading.Thread(target=self._drain, daemon=True)
        self._thread.start()

    def _drain(self) -> None:
        # Keep reading so the child never blocks on a full pty buffer.
        while not self._done.is_set():
            readable, _, _ = select.select([self.master], [], [], 0.05)
            if readable:
                try:
                    data = os.read(self.master, 4096)
                except OSError:
                    return
                with self._lock:
                    self._chunks.append(data)

    def output(self) -> str:
        with self._lock:
            return b"".join(self._chunks).decode(errors="replace")

    def write(self, data: bytes) -> None:
        os.write(self.master, data)

    def mode(self) -> list:
        return termios.tcgetattr(self.slave)

    def is_raw(self) -> bool:
        return not self.mode()[3] & (termios.ICANON | termios.ECHO)

    def wait_output(self, text: str, timeout: float = 20.0) -> None:
        def seen() -> bool:
            if text in self.output():
                return True
            if self.proc.poll() is not None:
                raise AssertionError(f"exited with {self.proc.returncode} before printing {text!r}:\n"
                                     f"{self.output()[-3000:]}")
            return False

        wait_until(seen, timeout, f"{text!r} in the output:\n{self.output()[-3000:]}")

    def wait_exit(self, timeout: float = 20.0) -> int:
        try:
            return self.proc.wait(timeout=timeout)
        except subprocess.TimeoutExpired as err:
            raise AssertionError(f"still running after {timeout} s:\n{self.output()[-3000:]}") from err

    def close(self) -> None:
        stop_process_group(self.proc)
        self._done.set()
        self._thread.join(timeout=5)
        os.close(self.master)
        os.close(self.slave)


@pytest.fixture
def pty_run():
    """Factory: `with pty_run([...]) as p:` runs a command on a pseudo-terminal and always stops it."""

    @contextlib.contextmanager
    def run(cmd: Sequence[str]) -> Iterator[PtyProcess]:
        process = PtyProcess(cmd)
        try:
            yield process
        finally:
            process.close()

    return run
