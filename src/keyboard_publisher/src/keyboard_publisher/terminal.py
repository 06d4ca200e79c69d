"""Reading single key presses from a terminal, and always giving the terminal back.

`RawTerminal` switches a TTY to a raw-ish mode (no line buffering, no echo, no signals from Ctrl-C/Ctrl-Z,
so those arrive as keys; output processing stays on so "\\n" still starts a new line) and restores the saved
mode on exit, on exceptions, at interpreter exit (atexit) and when `StopSignals` ends the loop on
SIGINT/SIGTERM/SIGHUP. `KeyReader` waits for input with select() and parses escape sequences (arrows) into
key names with `KeyParser`.
"""

from __future__ import annotations

import atexit
import codecs
import contextlib
import os
import select
import signal
import termios
import threading
from types import FrameType, TracebackType

from compliant_common.errors import StackError

__all__ = ["ESCAPE_WAIT", "KeyParser", "KeyReader", "RawTerminal", "StopSignals", "TerminalError"]

# How long a lone ESC byte waits for the rest of an escape sequence before it counts as the Escape key.
ESCAPE_WAIT = 0.05

_CSI_FINAL = {"A": "up", "B": "down", "C": "right", "D": "left", "H": "home", "F": "end"}
_CSI_TILDE = {"1": "home", "2": "insert", "3": "delete", "4": "end", "5": "page_up", "6": "page_down",
              "7": "home", "8": "end"}
_CONTROL = {"\r": "enter", "\n": "enter", "\t": "tab", "\x7f": "backspace", "\x08": "backspace"}


class TerminalError(StackError, RuntimeError):
    """The file descriptor is not a terminal, or the terminal went away."""


class KeyParser:
    """Splits decoded terminal input into keys (characters, control characters, names of special keys).

    Input may arrive in pieces; an incomplete escape sequence or UTF-8 character is kept until the next
    `feed` or until `flush`.
    """

    def __init__(self) -> None:
        self._decoder = codecs.getincrementaldecoder("utf-8")(errors="replace")
        self._pending = ""

    @property
    def pending(self) -> bool:
        """True while an escape sequence is incomplete."""
        return bool(self._pending)

    def feed(self, data: bytes) -> list[str]:
        """Parses more input; returns the complete keys in it."""
        text = self._pending + self._decoder.decode(data)
        keys, self._pending = _parse(text, final=False)
        return keys

    def flush(self) -> list[str]:
        """Ends an incomplete sequence: a lone ESC is the Escape key."""
        text, self._pending = self._pending, ""
        return _parse(text, final=True)[0]


def _parse(text: str, final: bool) -> tuple[list[str], str]:
    keys: list[str] = []
    i = 0
    while i < len(text):
        char = text[i]
        if char != "\x1b":
            keys.append(_CONTROL.get(char, char))
            i += 1
            continue
        if i + 1 >= len(text):
            if not final:
                return keys, text[i:]
            keys.append("escape")
            break
        intro = text[i + 1]
        if intro not in "[O":
            keys.append("escape")  # ESC + key (Alt+key): the key follows as itself
            i += 1
            continue
        # CSI "ESC [ params final" or SS3 "ESC O final"; the final byte is in 0x40..0x7e.
        j = i + 2
        while j < len(text) and not ("\x40" <= text[j] <= "\x7e"):
            j += 1
        if j >= len(text):
            if not final:
                return keys, text[i:]
            keys.append("escape")
            i += 1
            continue
        params, end = text[i + 2 : j], text[j]
        if end == "~":
            keys.append(_CSI_TILDE.get(params.split(";")[0], "unknown"))
        else:
            keys.append(_CSI_FINAL.get(end, "unknown"))
        i = j + 1
    return keys, ""


class RawTerminal:
    """Context manager: the terminal on `fd` in raw mode inside, its saved mode restored on the way out.

    Args:
        fd: a file descriptor of a TTY (usually stdin).

    Raises:
        TerminalError: on enter, if `fd` is not a terminal.
    """

    def __init__(self, fd: int) -> None:
        self._fd = fd
        self._saved: list | None = None

    def __enter__(self) -> RawTerminal:
        if not os.isatty(self._fd):
            raise TerminalError(f"file descriptor {self._fd} is not a terminal")
        saved = termios.tcgetattr(self._fd)
        raw = termios.tcgetattr(self._fd)
        # Ctrl-S/Ctrl-Q and CR translation off, so every key arrives as typed.
        raw[0] &= ~(termios.IXON | termios.ICRNL | termios.INLCR | termios.IGNCR | termios.ISTRIP
                    | termios.BRKINT)
        raw[3] &= ~(termios.ICANON | termios.ECHO | termios.ISIG | termios.IEXTEN)
        raw[6][termios.VMIN] = 1
        raw[6][termios.VTIME] = 0
        self._saved = saved
        atexit.register(self.restore)  # in case something exits the interpreter without unwinding
        termios.tcsetattr(self._fd, termios.TCSADRAIN, raw)
        return self

    def restore(self) -> None:
        """Puts the saved mode back (idempotent; a vanished terminal is ignored)."""
        saved, self._saved = self._saved, None
        if saved is not None:
            with contextlib.suppress(termios.error, OSError):
                termios.tcsetattr(self._fd, termios.TCSADRAIN, saved)

    def __exit__(
        self, exc_type: type[BaseException] | None, exc: BaseException | None, tb: TracebackType | None
    ) -> None:
        self.restore()
        atexit.unregister(self.restore)


class KeyReader:
    """Reads key presses from a (raw-mode) terminal without blocking longer than asked.

    Args:
        fd: the terminal's file descriptor.
    """

    def __init__(self, fd: int) -> None:
        self._fd = fd
        self._parser = KeyParser()

    def read(self, timeout: float) -> list[str]:
        """Waits up to `timeout` s for input; returns the keys that arrived (empty on timeout).

        Raises:
            TerminalError: the terminal was closed (end of file or I/O error).
        """
        if not _readable(self._fd, max(timeout, 0.0)):
            return []
        keys = self._parser.feed(self._read_chunk())
        # Escape sequences arrive in one write; a lone ESC gets a short grace period for the rest.
        while self._parser.pending:
            if _readable(self._fd, ESCAPE_WAIT):
                keys += self._parser.feed(self._read_chunk())
            else:
                keys += self._parser.flush()
        return keys

    def _read_chunk(self) -> bytes:
        try:
            data = os.read(self._fd, 1024)
        except OSError as err:  # EIO: the other end of a pty went away
            raise TerminalError(f"terminal read failed: {err}") from err
        if not data:
            raise TerminalError("terminal closed (end of file)")
        return data


def _readable(fd: int, timeout: float) -> bool:
    readable, _, _ = select.select([fd], [], [], timeout)
    return bool(readable)


class StopSignals:
    """Context manager: SIGINT, SIGTERM and SIGHUP set `event` instead of killing the process.

    The loop polling `event` then unwinds normally, so `RawTerminal` restores the terminal. The previous
    handlers are restored on exit. Must be entered in the main thread.
    """

    SIGNALS = (signal.SIGINT, signal.SIGTERM, signal.SIGHUP)

    def __init__(self) -> None:
        self.event = threading.Event()
        self.received: int | None = None
        self._previous: dict[int, object] = {}

    def _handle(self, signum: int, frame: FrameType | None) -> None:
        self.received = signum
        self.event.set()

    def __enter__(self) -> StopSignals:
        for signum in self.SIGNALS:
            self._previous[signum] = signal.signal(signum, self._handle)
        return self

    def __exit__(
        self, exc_type: type[BaseException] | None, exc: BaseException | None, tb: TracebackType | None
    ) -> None:
        for signum, handler in self._previous.items():
            signal.signal(signum, handler)  # type: ignore[arg-type]
        self._previous.clear()
