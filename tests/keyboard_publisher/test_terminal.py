"""The terminal layer on a real pseudo-terminal: raw mode on and off, key parsing, signals."""

from __future__ import annotations

import os
import signal
import termios

import pytest
from keyboard_publisher.terminal import KeyParser, KeyReader, RawTerminal, StopSignals, TerminalError


@pytest.fixture
def pty_pair():
    master, slave = os.openpty()
    yield master, slave
    for fd in (master, slave):
        os.close(fd)


def is_raw(fd: int) -> bool:
    lflag = termios.tcgetattr(fd)[3]
    return not lflag & (termios.ICANON | termios.ECHO | termios.ISIG)


@pytest.mark.parametrize(
    ("chunks", "keys"),
    [
        ([b"w"], ["w"]),
        ([b"www"], ["w", "w", "w"]),
        ([b"\x1b[A\x1b[B\x1b[C\x1b[D"], ["up", "down", "right", "left"]),
        ([b"\x1bOA"], ["up"]),  # application cursor mode
        ([b"\x1b[1;5C"], ["right"]),  # Ctrl+Right: modifiers ignored
        ([b"\x1b[5~\x1b[6~\x1b[3~"], ["page_up", "page_down", "delete"]),
        ([b"\x1b[", b"A"], ["up"]),  # a sequence split across reads
        ([b"\xc3", b"\xa9"], ["é"]),  # a UTF-8 character split across reads
        ([b"\x03"], ["\x03"]),
        ([b"\r \x7f"], ["enter", " ", "backspace"]),
        ([b"\x1b[Z"], ["unknown"]),
    ],
)
def test_parser_splits_keys(chunks, keys):
    parser = KeyParser()
    got: list[str] = []
    for chunk in chunks:
        got += parser.feed(chunk)
    assert got == keys
    assert not parser.pending


def test_lone_escape_waits_then_is_the_escape_key():
    parser = KeyParser()
    assert parser.feed(b"w\x1b") == ["w"]
    assert parser.pending
    assert parser.flush() == ["escape"]


def test_raw_mode_inside_restored_after_and_after_an_exception(pty_pair):
    _, slave = pty_pair
    before = termios.tcgetattr(slave)
    assert not is_raw(slave)
    with RawTerminal(slave):
        assert is_raw(slave)
        # Output processing stays on so printed lines still start at column 0.
        assert termios.tcgetattr(slave)[1] & termios.OPOST
    assert termios.tcgetattr(slave) == before
    with pytest.raises(RuntimeError, match="crash"), RawTerminal(slave):
        assert is_raw(slave)
        raise RuntimeError("crash")
    assert termios.tcgetattr(slave) == before


def test_restore_is_idempotent_and_survives_a_closed_terminal():
    master, slave = os.openpty()
    terminal = RawTerminal(slave).__enter__()
    os.close(slave)
    os.close(master)
    terminal.restore()  # no exception although the terminal is gone
    terminal.restore()


def test_not_a_terminal_is_refused():
    read_end, write_end = os.pipe()
    try:
        with pytest.raises(TerminalError, match="not a terminal"), RawTerminal(read_end):
            pass
    finally:
        os.close(read_end)
        os.close(write_end)


def test_reader_reads_keys_and_escape_sequences(pty_pair):
    master, slave = pty_pair
    reader = KeyReader(slave)
    with RawTerminal(slave):
        assert reader.read(0.0) == []
        os.write(master, b"w\x1b[A\x03")
        assert reader.read(5.0) == ["w", "up", "\x03"]
        os.write(master, b"\x1b")
        assert reader.read(5.0) == ["escape"]


def test_reader_reports_a_closed_terminal():
    master, slave = os.openpty()
    reader = KeyReader(slave)
    os.close(master)
    try:
        with pytest.raises(TerminalError):
            reader.read(5.0)
    finally:
        os.close(slave)


def test_stop_signals_set_the_event_and_restore_handlers():
    previous = signal.getsignal(signal.SIGTERM)
    with StopSignals() as signals:
        os.kill(os.getpid(), signal.SIGTERM)
        assert signals.event.wait(5.0)
        assert signals.received == signal.SIGTERM
    assert signal.getsignal(signal.SIGTERM) is previous
