"""Keys and a progress line for a command that runs in a terminal (``rosmc replay``).

:class:`KeyReader` puts the terminal into cbreak mode (each key arrives at once and is not
echoed; Ctrl-C still interrupts) and hands every key to a callback, by name, from a
thread of its own. It restores the terminal's mode on every way out: leaving its ``with``
block normally, by an exception or by Ctrl-C, and at interpreter exit, so a shell is never
left without echo. :class:`ProgressLine` keeps one status line redrawn in place at the
bottom of a terminal, with other output scrolling above it; written to a file or a pipe,
it prints the status as lines of their own, only when it says something new.
"""

from __future__ import annotations

import atexit
import contextlib
import logging
import os
import select
import termios
import threading
import tty
from collections.abc import Callable, Hashable
from types import TracebackType
from typing import Any, Self, TextIO

_log = logging.getLogger(__name__)

KEYS = {b" ": "space", b"\x1b[C": "right", b"\x1b[D": "left", b"\x1b[A": "up", b"\x1b[B": "down"}
"""Names of the keys that are not plain characters (arrows arrive as escape sequences)."""
ERASE = "\r\x1b[K"
"""Back to the start of the line, and erase it."""


def is_terminal(stream: TextIO) -> bool:
    """Whether ``stream`` is a terminal (not a file, a pipe or closed)."""
    try:
        return stream.isatty()
    except (ValueError, OSError):
        return False


def keys_from(stream: TextIO) -> bool:
    """Whether keys can be read from ``stream``: a terminal whose foreground we run in.

    A job in the background of its terminal (``rosmc replay ... &``) must leave the terminal
    alone: changing its mode would stop the job (SIGTTOU), and the keys are the shell's.
    """
    if not is_terminal(stream):
        return False
    try:
        return os.tcgetpgrp(stream.fileno()) == os.getpgrp()
    except OSError:  # not this process's controlling terminal: no job control applies
        return True


def key_names(data: bytes) -> list[str]:
    """The keys in bytes read from a terminal: ``space``, ``left``, ``q``, ``[``, ...

    Unknown escape sequences are left out; other bytes are their characters.
    """
    names = []
    index = 0
    while index < len(data):
        if data[index : index + 2] == b"\x1b[" and index + 2 < len(data):
            sequence = data[index : index + 3]
            if sequence in KEYS:
                names.append(KEYS[sequence])
            index += 3
            continue
        char = data[index : index + 1]
        names.append(KEYS.get(char) or char.decode("latin-1"))
        index += 1
    return names


class KeyReader:
    """Reads keys from a terminal while its ``with`` block runs; calls ``on_key(name)``.

    The callback runs on the reader's thread; an exception in it is logged and the
    reading goes on.

    Args:
        stream: The terminal to read (usually ``sys.stdin``); see :func:`is_terminal`.
        on_key: Called with each key's name (see :func:`key_names`).
    """

    def __init__(self, stream: TextIO, on_key: Callable[[str], None]) -> None:
        self._fd = stream.fileno()
        self._on_key = on_key
        self._saved: list[Any] | None = None
        self._wake_read, self._wake_write = os.pipe()
        self._thread = threading.Thread(target=self._read, name="rosmc-keys", daemon=True)

    def __enter__(self) -> Self:
        self._saved = termios.tcgetattr(self._fd)
        atexit.register(self._restore)  # also if the process leaves without unwinding
        tty.setcbreak(self._fd, termios.TCSANOW)
        self._thread.start()
        return self

    def __exit__(
        self,
        exc_type: type[BaseException] | None,
        exc: BaseException | None,
        tb: TracebackType | None,
    ) -> None:
        self.close()

    def close(self) -> None:
        """Stop reading and give the terminal its mode back (safe to call twice)."""
        with contextlib.suppress(OSError):
            os.write(self._wake_write, b"x")
        if self._thread.is_alive() and self._thread is not threading.current_thread():
            self._thread.join(timeout=2.0)
        self._restore()
        atexit.unregister(self._restore)
        for fd in (self._wake_read, self._wake_write):
            with contextlib.suppress(OSError):
                os.close(fd)

    def _restore(self) -> None:
        saved, self._saved = self._saved, None
        if saved is not None:
            with contextlib.suppress(termios.error, OSError):
                termios.tcsetattr(self._fd, termios.TCSADRAIN, saved)

    def _read(self) -> None:
        while True:
            try:
                ready, _, _ = select.select([self._fd, self._wake_read], [], [])
                if self._wake_read in ready:
                    return
                data = os.read(self._fd, 64)
            except OSError:
                return
            if not data:
                return  # the terminal went away
            for name in key_names(data):
                try:
                    self._on_key(name)
                except Exception:  # a key that fails must not end the reading
                    _log.exception("the %r key failed", name)


class ProgressLine:
    """A status line: redrawn in place on a terminal, printed sparsely elsewhere.

    Args:
        out: Where to write.
        terminal: Whether ``out`` is a terminal (see :func:`is_terminal`).
    """

    def __init__(self, out: TextIO, terminal: bool) -> None:
        self._out = out
        self._terminal = terminal
        self._lock = threading.Lock()
        self._text = ""
        self._said: Hashable = None

    def show(self, text: str, news: Hashable) -> None:
        """Show ``text`` as the status now.

        On a terminal the line is redrawn; elsewhere ``text`` is printed as a line only if
        ``news`` (what the status says, coarsely) differs from the last one printed.
        """
        with self._lock:
            if self._terminal:
                text = text[: self._width() - 1]  # a wrapped line cannot be redrawn in place
                if text != self._text:
                    self._text = text
                    self._write(ERASE + text)
            elif news != self._said:
                self._said = news
                self._write(text + "\n")

    def print(self, line: str) -> None:
        """Print ``line`` above the status line."""
        with self._lock:
            if self._terminal:
                self._write(f"{ERASE}{line}\n{self._text}")
            else:
                self._write(line + "\n")

    def close(self) -> None:
        """Erase the status line from a terminal (the output above it stays)."""
        with self._lock:
            if self._terminal and self._text:
                self._write(ERASE)
            self._text = ""

    def _width(self) -> int:
        try:
            columns = os.get_terminal_size(self._out.fileno()).columns
        except (OSError, ValueError):
            columns = 0
        return columns if columns > 1 else 10_000  # unknown (0): do not clip

    def _write(self, text: str) -> None:
        self._out.write(text)
        self._out.flush()
