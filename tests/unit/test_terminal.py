"""The terminal helpers of ``rosmc replay``: key names, the progress line, the mode restored.

A real pseudo-terminal stands in for the user's: keys are written to its master side and
the reader gets them from the slave side, whose mode must be back as it was however the
``with`` block ends.
"""

from __future__ import annotations

import io
import os
import pty
import termios
import threading
from collections.abc import Iterator

import pytest

from rosmc_server.cli.terminal import ERASE, KeyReader, ProgressLine, is_terminal, key_names


def test_keys_are_named() -> None:
    assert key_names(b" q[]") == ["space", "q", "[", "]"]
    assert key_names(b"\x1b[D\x1b[C\x1b[A\x1b[B") == ["left", "right", "up", "down"]
    assert key_names(b"\x1b[Zx") == ["x"], "an unknown escape sequence is left out"
    assert key_names(b"\x1b") == ["\x1b"]


def test_in_a_pipe_the_progress_is_printed_only_when_it_says_something_new() -> None:
    out = io.StringIO()
    line = ProgressLine(out, terminal=False)
    line.show("at 0 s", news=0)
    line.show("at 3 s", news=0)
    line.print("an event")
    line.show("at 10 s", news=1)
    line.close()
    assert out.getvalue() == "at 0 s\nan event\nat 10 s\n"


def test_on_a_terminal_the_line_is_redrawn_under_the_output() -> None:
    out = io.StringIO()
    line = ProgressLine(out, terminal=True)
    line.show("at 0 s", news=0)
    line.show("at 0 s", news=0)  # unchanged: nothing written
    line.print("an event")
    line.show("at 1 s", news=0)
    line.close()
    assert out.getvalue() == (f"{ERASE}at 0 s{ERASE}an event\nat 0 s{ERASE}at 1 s{ERASE}")


@pytest.fixture
def tty() -> Iterator[tuple[int, io.TextIOWrapper]]:
    master, slave = pty.openpty()
    stream = os.fdopen(slave, "r", closefd=True)
    yield master, stream
    stream.close()
    os.close(master)


def test_keys_arrive_by_name_and_the_mode_comes_back(tty: tuple[int, io.TextIOWrapper]) -> None:
    master, stream = tty
    assert is_terminal(stream) and not is_terminal(io.StringIO())
    before = termios.tcgetattr(stream.fileno())
    heard: list[str] = []
    got_all = threading.Event()

    def on_key(name: str) -> None:
        heard.append(name)
        if name == "q":
            got_all.set()

    with KeyReader(stream, on_key):
        mode = termios.tcgetattr(stream.fileno())
        assert not mode[3] & (termios.ICANON | termios.ECHO), "cbreak: no line editing, no echo"
        assert mode[3] & termios.ISIG, "Ctrl-C still interrupts"
        os.write(master, b" \x1b[Cq")
        assert got_all.wait(10.0)
    assert heard == ["space", "right", "q"]
    assert termios.tcgetattr(stream.fileno()) == before


def test_the_mode_comes_back_after_an_exception_and_a_failing_key(
    tty: tuple[int, io.TextIOWrapper],
) -> None:
    master, stream = tty
    before = termios.tcgetattr(stream.fileno())
    heard = threading.Event()

    def on_key(name: str) -> None:
        if name == "x":
            raise RuntimeError("x fails")
        heard.set()

    with pytest.raises(KeyboardInterrupt), KeyReader(stream, on_key):
        os.write(master, b"x")
        os.write(master, b"y")
        assert heard.wait(10.0), "a failing key does not end the reading"
        raise KeyboardInterrupt
    assert termios.tcgetattr(stream.fileno()) == before
