"""How far the replay's playing thread got, for the steering calls that answer after it.

A seek answers once the state at the new position is out, and a pause once every record
due until the pause is out: a record that came due just before a pause is published after
it by the playing thread, and the pause's answer must name the revision subscribers end
with. The steering calls run on other threads (the control service, the keys); they wait
here, at most :data:`ANSWER_WITHIN` seconds, and not at all while nothing plays.
"""

from __future__ import annotations

import logging
import threading
import time
from collections.abc import Callable

_log = logging.getLogger(__name__)

ANSWER_WITHIN = 10.0
"""Seconds a steering call waits for the playing thread before it answers anyway."""


class ReplayProgress:
    """What the playing thread has published: the seeks handled and the next record.

    Args:
        lock: The replayer's lock (what was published is read and written under it).
    """

    def __init__(self, lock: threading.RLock) -> None:
        self.condition = threading.Condition(lock)
        self._playing = False
        self._seeks = 0  # the number of the last seek whose state is out
        self._next_record = 0  # the playlist index the playing thread publishes next

    def playing(self, playing: bool) -> None:
        """The playing thread starts (True) or ends (False: nobody waits for it any more)."""
        with self.condition:
            self._playing = playing
            self.condition.notify_all()

    def seek_out(self, seeks: int) -> None:
        """The state at seek number ``seeks`` is out (call with :attr:`condition` held)."""
        self._seeks = seeks
        self.condition.notify_all()

    def next_record(self, index: int) -> None:
        """The playing thread publishes record ``index`` next (those before are out)."""
        with self.condition:
            self._next_record = index
            self.condition.notify_all()

    def await_seek(self, seeks: int, stopped: threading.Event) -> None:
        """Wait until the state at seek number ``seeks`` is out."""
        self._await(lambda: self._seeks < seeks, stopped, "seek")

    def await_due(self, due: Callable[[int], bool], stopped: threading.Event) -> None:
        """Wait until the next record to publish is no longer ``due`` (index -> bool)."""
        self._await(lambda: due(self._next_record), stopped, "pause")

    def _await(self, behind: Callable[[], bool], stopped: threading.Event, what: str) -> None:
        deadline = time.monotonic() + ANSWER_WITHIN
        with self.condition:
            while self._playing and behind() and not stopped.is_set():
                left = deadline - time.monotonic()
                if left <= 0:
                    _log.warning("the replay took longer than %g s to %s", ANSWER_WITHIN, what)
                    return
                self.condition.wait(left)
