"""``rosmc replay`` at work: the replayed events, a progress line and, in a terminal, keys.

Keys (when stdin is a terminal): space pauses and resumes, left and right arrows seek
10 s back and forth, ``[`` and ``]`` halve and double the rate, ``q`` ends the replay.
The progress line (time / duration, revision, rate, paused) is redrawn in place on a
terminal and printed every 10 s of recording time, or when it was paused, resumed, moved
or sped up, to a file or a pipe. SIGTERM and SIGHUP end the replay as ``q`` does, so the
terminal gets its mode back.
"""

from __future__ import annotations

import contextlib
import signal
import threading
from collections.abc import Hashable, Iterator
from types import FrameType
from typing import TYPE_CHECKING, TextIO

from ..core import MissionEvent, RosmcError
from ..text import format_event
from .terminal import KeyReader, ProgressLine

if TYPE_CHECKING:
    from ..recording.playback import PlaybackStatus
    from ..ros.replayer import RecordingReplayer

SEEK_STEP = 10.0
"""Seconds the arrow keys move the replay."""
REDRAW = 0.25
"""Wall seconds between two looks at the replay for the progress line."""
SPARSE = 10.0
"""Recording seconds between two progress lines in a file or a pipe."""
KEYS_HELP = "space pause/play, \u2190/\u2192 10 s, [ ] rate, q quit"


def progress_text(status: PlaybackStatus, terminal: bool) -> str:
    """The progress line: ``  42.50 / 187.00 s  r120  5x  paused``."""
    state = "end" if status.ended else ("paused" if status.paused else "playing")
    text = (
        f"{status.position:8.2f} / {status.duration:.2f} s  r{status.revision}  "
        f"{status.rate:g}x  {state}"
    )
    return f"{text}   ({KEYS_HELP})" if terminal else f"[{status.position:8.2f} s] -- {text} --"


def progress_news(status: PlaybackStatus) -> Hashable:
    """What a sparse progress line is printed for: 10 s more, pause, seek, rate, the end."""
    return (int(status.position // SPARSE), status.paused, status.rate, status.seeks, status.ended)


class ReplaySession:
    """Shows one replay's events and progress, and steers it with keys.

    Args:
        out: Where events and progress go.
        out_terminal: Whether ``out`` is a terminal (redraw the progress line in place).
        keys: The terminal to read keys from (None: no keys).
        progress: Whether to show progress and events at all (not with --json).
    """

    def __init__(
        self, out: TextIO, out_terminal: bool, keys: TextIO | None, progress: bool
    ) -> None:
        self._line = ProgressLine(out, out_terminal)
        self._terminal = out_terminal
        self._keys = keys
        self._progress = progress
        self._player: RecordingReplayer | None = None
        self._done = threading.Event()

    def event(self, revision: int, event: MissionEvent | None, seconds: float) -> None:
        """Print one replayed event (the replayer's ``on_event``)."""
        if self._progress:
            line = format_event(event) if event else f"r{revision} (an event that does not decode)"
            self._line.print(f"[{seconds:8.2f} s] {line}")

    def run(self, player: RecordingReplayer) -> int:
        """Run ``player`` to its end (or ``q``); return the last revision it showed."""
        self._player = player
        with contextlib.ExitStack() as stack:
            stack.enter_context(self._signals_end(player))
            if self._keys is not None:
                stack.enter_context(KeyReader(self._keys, self._on_key))
            if self._progress:
                ticker = threading.Thread(target=self._tick, name="rosmc-progress", daemon=True)
                ticker.start()
                # Undone last to first: stop the ticker, then erase its line.
                stack.callback(self._line.close)
                stack.callback(ticker.join, 2.0)
                stack.callback(self._done.set)
            return player.run()

    def _tick(self) -> None:
        assert self._player is not None
        while True:
            status = self._player.status()
            self._line.show(progress_text(status, self._terminal), progress_news(status))
            if self._done.wait(REDRAW):
                return

    def _on_key(self, name: str) -> None:
        player = self._player
        assert player is not None
        try:
            if name == "space":
                status = player.status()
                if status.paused or status.ended:
                    player.resume()
                else:
                    player.pause()
            elif name in ("left", "right"):
                player.seek(SEEK_STEP if name == "right" else -SEEK_STEP, relative=True)
            elif name in ("[", "]"):
                rate = player.status().rate
                player.set_rate(rate * 2 if name == "]" else rate / 2)
            elif name in ("q", "Q"):
                player.stop()
        except RosmcError as err:  # e.g. a rate out of range: say so above the line
            self._line.print(f"rosmc: {err}")

    @contextlib.contextmanager
    def _signals_end(self, player: RecordingReplayer) -> Iterator[None]:
        """SIGTERM and SIGHUP end the replay (so every ``finally`` runs) while it plays."""
        if threading.current_thread() is not threading.main_thread():
            yield
            return

        def end(_signum: int, _frame: FrameType | None) -> None:
            player.stop()

        previous = {sig: signal.signal(sig, end) for sig in (signal.SIGTERM, signal.SIGHUP)}
        try:
            yield
        finally:
            for sig, handler in previous.items():
                signal.signal(sig, handler)
