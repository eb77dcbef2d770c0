"""Where a replay is in its recording: the playback clock, the records in time order, TF stamps.

Pure Python (no rospy), so the rules are tested without a ROS graph. The replayer's
thread waits on a :class:`PlaybackClock` for each record's time; key presses, the
replay's control service and tests move the clock from other threads (pause, resume,
seek, rate), which wakes the waiting thread at once. Times are seconds since the
recording started, as everywhere in the recording commands.

Typical use (what :class:`~rosmc_server.ros.replayer.RecordingReplayer` does)::

    clock = PlaybackClock(duration=history.duration, start=0.0, rate=5.0)
    playlist = Playlist(records, history.start)
    index = playlist.index_after(clock.status().position)
    if clock.wait(playlist.offset(index)):
        publish(playlist.records[index])
    # else: paused, resumed, moved or closed meanwhile; look at clock.status()
"""

from __future__ import annotations

import bisect
import math
import threading
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass

from rosmc_server.core import InvalidRequest
from rosmc_server.recording.reader import JournalRecord

MIN_RATE = 1 / 64
MAX_RATE = 1024.0
"""The rates a replay accepts (a rate outside is refused, not clipped)."""


@dataclass(frozen=True)
class PlaybackStatus:
    """A replay's position and settings at one moment.

    Attributes:
        position: Seconds since the recording started.
        duration: The recording's length (s).
        rate: Speed-up: 2.0 plays twice as fast as recorded.
        paused: Whether the position stands still.
        seeks: How often the position was moved (by a seek) since the replay started.
        revision: The mission revision published at the position (-1: not known here).
    """

    position: float
    duration: float
    rate: float
    paused: bool
    seeks: int
    revision: int = -1

    @property
    def ended(self) -> bool:
        """Whether the position is at the end of the recording."""
        return self.position >= self.duration


class PlaybackClock:
    """The position of a replay, advancing ``rate`` recording seconds per second unless paused.

    Thread-safe. Every change (pause, resume, seek, rate, close) wakes :meth:`wait`.

    Args:
        duration: The recording's length (s); the position stays within 0 and it.
        start: The position to begin at (s).
        rate: The speed-up to begin with.
        monotonic: The clock to measure time with (seconds; injected by tests).
    """

    def __init__(
        self,
        duration: float,
        start: float = 0.0,
        rate: float = 1.0,
        monotonic: Callable[[], float] = time.monotonic,
    ) -> None:
        self._duration = max(0.0, duration)
        self._rate = _checked_rate(rate)
        self._monotonic = monotonic
        self._changed = threading.Condition()
        self._anchor = self._clamp(start)  # the position at _since
        self._since = monotonic()
        self._paused = False
        self._started = False
        self._seeks = 0
        self._changes = 0
        self._closed = False

    # -- reading -----------------------------------------------------------------------
    def status(self) -> PlaybackStatus:
        """Where the replay is now."""
        with self._changed:
            return self._status()

    @property
    def changes(self) -> int:
        """How many changes (pause, resume, seek, rate, close) there were so far."""
        with self._changed:
            return self._changes

    # -- steering (any thread) -----------------------------------------------------------
    def start(self) -> None:
        """Let the position advance from now on (it stands still until then).

        The replay calls it once subscribers had time to connect; not a change.
        """
        with self._changed:
            self._since, self._started = self._monotonic(), True

    def pause(self) -> PlaybackStatus:
        """Stop the position where it is (nothing happens if paused already)."""
        with self._changed:
            if not self._paused:
                self._rebase()
                self._paused = True
                self._changed_now()
            return self._status()

    def resume(self) -> PlaybackStatus:
        """Go on from the position; at the end of the recording, play it again from the start."""
        with self._changed:
            if self._position() >= self._duration:
                self._move(0.0)
            if self._paused:
                self._paused = False
                self._since = self._monotonic()
                self._changed_now()
            return self._status()

    def seek(self, seconds: float, *, relative: bool = False) -> PlaybackStatus:
        """Move to ``seconds`` since the start (or from the position); clamped to the recording.

        Raises:
            InvalidRequest: ``seconds`` is not a number.
        """
        if not math.isfinite(seconds):
            raise InvalidRequest(f"a replay seeks to a number of seconds, got {seconds}")
        with self._changed:
            self._move(self._position() + seconds if relative else seconds)
            return self._status()

    def set_rate(self, rate: float) -> PlaybackStatus:
        """Play ``rate`` times as fast as recorded from now on.

        Raises:
            InvalidRequest: ``rate`` is outside :data:`MIN_RATE` to :data:`MAX_RATE`.
        """
        rate = _checked_rate(rate)
        with self._changed:
            self._rebase()
            self._rate = rate
            self._changed_now()
            return self._status()

    def close(self) -> None:
        """Wake every waiter for good: the replay ends."""
        with self._changed:
            self._closed = True
            self._changed_now()

    # -- waiting (the replayer's thread) ---------------------------------------------------
    def wait(self, until: float | None, since: int | None = None) -> bool:
        """Block until the position reaches ``until`` or something changes.

        Args:
            until: The position to wait for (s); None waits for a change only.
            since: A value of :attr:`changes`: return at once if there were more changes
                since (default: the value now).

        Returns:
            True if the position reached ``until``; False after a change (then look at
            :meth:`status`) or once the clock is closed.
        """
        with self._changed:
            changes = self._changes if since is None else since
            while not self._closed and self._changes == changes:
                left = self._seconds_until(until)
                if left is not None and left <= 0:
                    return True
                self._changed.wait(left)
            return False

    # -- internals (with the lock held) -----------------------------------------------------
    def _position(self) -> float:
        if self._paused or not self._started:
            return self._anchor
        elapsed = (self._monotonic() - self._since) * self._rate
        return self._clamp(self._anchor + elapsed)

    def _seconds_until(self, until: float | None) -> float | None:
        """Wall seconds until the position reaches ``until``; None if it never does by itself."""
        if until is None:
            return None
        ahead = until - self._position()
        if ahead <= 0:
            return 0.0
        if self._paused or not self._started or self._position() >= self._duration:
            return None
        return ahead / self._rate

    def _rebase(self) -> None:
        """Count on from the position now (before the rate or the pausing changes)."""
        self._anchor, self._since = self._position(), self._monotonic()

    def _move(self, seconds: float) -> None:
        self._anchor, self._since = self._clamp(seconds), self._monotonic()
        self._seeks += 1
        self._changed_now()

    def _changed_now(self) -> None:
        self._changes += 1
        self._changed.notify_all()

    def _clamp(self, seconds: float) -> float:
        return min(max(seconds, 0.0), self._duration)

    def _status(self) -> PlaybackStatus:
        return PlaybackStatus(
            self._position(), self._duration, self._rate, self._paused, self._seeks
        )


def _checked_rate(rate: float) -> float:
    if not MIN_RATE <= rate <= MAX_RATE:
        raise InvalidRequest(
            f"the rate must be between {MIN_RATE:g} and {MAX_RATE:g} (a speed-up), got {rate}"
        )
    return float(rate)


class Playlist:
    """A recording's records in log-time order, found by their time in the recording.

    Args:
        records: The records (any order; records of equal log time keep their order).
        start: Log time (ns) of time 0 of the recording.
    """

    def __init__(self, records: Sequence[JournalRecord], start: int) -> None:
        self.records = sorted(records, key=_log_time)
        self._start = start
        self._offsets = [self._seconds(r.log_time) for r in self.records]
        self._by_topic: dict[str, list[int]] = {}
        for index, record in enumerate(self.records):
            self._by_topic.setdefault(record.topic, []).append(index)

    def __len__(self) -> int:
        return len(self.records)

    def offset(self, index: int) -> float:
        """When record ``index`` was recorded (s since the recording started)."""
        return self._offsets[index]

    def index_after(self, seconds: float) -> int:
        """The first record recorded after ``seconds`` (``len(self)`` if none is)."""
        return bisect.bisect_right(self._offsets, seconds)

    def latest(self, topic: str, seconds: float) -> JournalRecord | None:
        """The last record of ``topic`` recorded at or before ``seconds`` (None if none was)."""
        indexes = self._by_topic.get(topic, [])
        count = bisect.bisect_right(indexes, self.index_after(seconds) - 1)
        return self.records[indexes[count - 1]] if count else None

    def earliest(self, topic: str) -> JournalRecord | None:
        """The first record of ``topic`` (None if the recording has none)."""
        indexes = self._by_topic.get(topic)
        return self.records[indexes[0]] if indexes else None

    def records_of(self, topic: str) -> list[JournalRecord]:
        """Every record of ``topic``, in time order."""
        return [self.records[index] for index in self._by_topic.get(topic, [])]

    def _seconds(self, log_time: int) -> float:
        return (log_time - self._start) / 1e9


class StampShift:
    """Keeps replayed TF stamps from going back in time when the replay seeks backwards.

    TF listeners (rviz, tf2) drop transforms older than what they hold by more than their
    cache (10 s), so after a seek back the replayed stamps are shifted forward by a constant
    just past the newest stamp published. Plain playing never shifts (0 ns): stamps stay
    as recorded. The shift never shrinks, so stamps only go forward.
    """

    MARGIN = 1_000_000
    """Nanoseconds the first stamp after a seek back lies past the newest one published."""

    def __init__(self) -> None:
        self.shift = 0
        """Nanoseconds added to every recorded stamp now."""
        self._newest: int | None = None
        self._moved = False

    def moved(self) -> None:
        """The replay seeked: the next stamps may lie before those published."""
        self._moved = True

    def apply(self, stamps: Sequence[int]) -> int:
        """Take the recorded stamps (ns) of one message to publish; return the shift for them."""
        if not stamps:
            return self.shift
        if self._moved and self._newest is not None:
            self.shift = max(self.shift, self._newest + self.MARGIN - min(stamps))
        self._moved = False
        newest = max(stamps) + self.shift
        self._newest = newest if self._newest is None else max(self._newest, newest)
        return self.shift


def _log_time(record: JournalRecord) -> int:
    return record.log_time
