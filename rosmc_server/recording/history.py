"""The mission at every revision of a journal, for people reviewing what happened.

:class:`MissionHistory` reads a journal once: it starts from the first snapshot,
applies every journaled event with :meth:`Mission.replay` and starts over from
the snapshot that follows a ``MISSION_REPLACED`` event (such an event carries no
content). It keeps a copy of the content every few hundred revisions, so any
revision is rebuilt by replaying a short run of events. Times are seconds since
the recording started (its first record) unless a log time (ns) is asked for.

Typical use::

    history = MissionHistory.from_journal("bags/mission_20260101_120000.mcap")
    state = history.at_time(42.0)  # a MissionState
    lanes = history.timeline().lanes
"""

from __future__ import annotations

import bisect
from dataclasses import dataclass
from pathlib import Path

from rosmc_server.conversions import event_from_msg, mission_from_msg
from rosmc_server.core import (
    EventKind,
    InvalidRequest,
    MissionContent,
    MissionEvent,
    MissionState,
    NotFound,
    RosmcError,
)
from rosmc_server.core.updates import apply_event
from rosmc_server.interface import EVENTS_TOPIC, MISSION_TOPIC, ROBOT_REPORTS_TOPIC
from rosmc_server.recording.damage import skipped_line
from rosmc_server.recording.errors import JournalError
from rosmc_server.recording.reader import JournalRecord, JournalResult, feed, read_journal
from rosmc_server.recording.revisions import Gap, RevisionWalk
from rosmc_server.recording.timeline import Timeline, TimelineBuilder

CHECKPOINT_EVERY = 256
"""Revisions between two kept copies of the content (bounds the replay per lookup)."""


@dataclass(frozen=True)
class Revision:
    """One revision of the mission in a recording.

    Attributes:
        revision: The mission revision.
        log_time: When it was journaled (ns since the epoch).
        kind: The event that produced it; None for a snapshot the history (re)started from.
        summary: The event's one-sentence summary ("" for a snapshot).
    """

    revision: int
    log_time: int
    kind: EventKind | None
    summary: str


@dataclass
class _Entry:
    info: Revision
    event: MissionEvent | None
    checkpoint: MissionContent | None


class MissionHistory:
    """Every revision of the mission a journal holds; build it with :meth:`from_journal`."""

    def __init__(self, result: JournalResult) -> None:
        """Replay ``result`` (a read journal); raises JournalError without a snapshot."""
        self.path = result.path
        self.warnings: tuple[str, ...] = result.warnings
        """What reading the file found wrong (a cut-off tail, undecodable records)."""
        if not result.records:
            raise JournalError(f"journal {result.path} holds no records")
        self.start = min(record.log_time for record in result.records)
        """Log time (ns) of the first record: time 0 of the recording."""
        self.end = max(record.log_time for record in result.records)
        """Log time (ns) of the last record."""
        self._entries: list[_Entry] = []
        self._problems: list[str] = []
        self._mission: MissionState | None = None
        self._timeline = TimelineBuilder(self.start)
        self.gaps: tuple[Gap, ...] = ()
        """The revisions that cannot be rebuilt (damaged or missing records)."""
        self.damage = result.damage
        """The damaged byte ranges reading skipped."""
        self._build(result)
        skipped = skipped_line(self.path, self.damage, self.gaps)
        self.problems: tuple[str, ...] = (skipped,) if skipped else ()
        self.problems += tuple(f"journal {self.path}: {text}" for text in self._problems)
        """What was skipped (one line: damaged bytes and the revisions they cost) and any
        other revision that could not be rebuilt, one sentence each (empty when intact)."""
        self._revisions = [entry.info.revision for entry in self._entries]
        self._times = [entry.info.log_time for entry in self._entries]
        self._cache: tuple[int, MissionState] | None = None

    @classmethod
    def from_journal(cls, path: str | Path) -> MissionHistory:
        """Read and replay the journal at ``path``.

        Raises:
            JournalError: The file is not a readable journal or holds no snapshot.
        """
        return cls(read_journal(path, (MISSION_TOPIC, EVENTS_TOPIC, ROBOT_REPORTS_TOPIC)))

    # -- queries ---------------------------------------------------------------------
    @property
    def revisions(self) -> tuple[Revision, ...]:
        """Every revision the history can show, oldest first."""
        return tuple(entry.info for entry in self._entries)

    @property
    def duration(self) -> float:
        """Seconds from the first to the last record."""
        return self.seconds(self.end)

    def seconds(self, log_time: int) -> float:
        """A log time (ns) as seconds since the recording started."""
        return (log_time - self.start) / 1e9

    def at_revision(self, revision: int) -> MissionState:
        """The mission at ``revision``.

        Raises:
            NotFound: The recording does not hold that revision.
        """
        index = bisect.bisect_left(self._revisions, revision)
        if index == len(self._revisions) or self._revisions[index] != revision:
            raise NotFound(
                f"journal {self.path} holds no revision {revision} (it holds "
                f"{self._revisions[0]} to {self._revisions[-1]}"
                + (", with gaps)" if self.problems else ")")
            )
        return self._state(index)

    def at_time(self, t: float, *, log_time: bool = False) -> MissionState:
        """The mission as it was at ``t`` seconds since the start (or at log time ``t`` ns).

        The mission before the first snapshot is that snapshot; after the last
        record, the last revision.

        Raises:
            InvalidRequest: ``t`` is negative (or not a number).
        """
        if not t >= 0:
            raise InvalidRequest(f"a time must be 0 or more, got {t}")
        return self._state(self._index_of(int(t) if log_time else self._log_time(t)))

    def revision_at(self, t: float) -> Revision:
        """The revision current ``t`` seconds after the start."""
        return self._entries[self._index_of(self._log_time(max(t, 0.0)))].info

    def timeline(self) -> Timeline:
        """Every robot's skill executions, barrier waits and barrier releases."""
        return self._timeline.build(self.seconds(self.end))

    # -- building ----------------------------------------------------------------------
    def _log_time(self, seconds: float) -> int:
        return self.start + round(seconds * 1e9)

    def _index_of(self, log_time: int) -> int:
        """The last entry journaled at or before ``log_time`` (the first if none was)."""
        return max(0, bisect.bisect_right(self._times, log_time) - 1)

    def _state(self, index: int) -> MissionState:
        start = index
        while self._entries[start].checkpoint is None:
            start -= 1
        cached = self._cache
        if cached is not None and start <= cached[0] <= index:
            start, state = cached  # sequential lookups replay only the new events
        else:
            state = _state(self._entries[start].checkpoint, self._revisions[start])
        for entry in self._entries[start + 1 : index + 1]:
            if entry.checkpoint is not None:
                state = _state(entry.checkpoint, entry.info.revision)
            else:
                assert entry.event is not None
                apply_event(state, entry.event)
        self._cache = (index, state)
        return MissionState(state.content(), state.revision)

    def _build(self, result: JournalResult) -> None:
        walk: RevisionWalk[JournalRecord, JournalRecord] = RevisionWalk(self._restart, self._apply)
        self._since_checkpoint = 0
        for record in result.records:
            if record.topic == ROBOT_REPORTS_TOPIC:
                self._timeline.report(record.message, record.log_time)
            else:
                feed(walk, record)
        walk.finish()
        if walk.unacknowledged is not None:
            self._problems.append(
                f"revision {walk.unacknowledged} replaced the mission, but the journal ends "
                "before the new mission's snapshot; it is left out"
            )
        self.gaps = tuple(walk.gaps)
        if not self._entries:
            raise JournalError(f"journal {self.path} holds no mission snapshot to start from")

    def _restart(self, record: JournalRecord, replacing: JournalRecord | None) -> None:
        """(Re)start the history from a snapshot (of a replacement, if given)."""
        revision = int(record.message.revision)
        info = Revision(revision, self._next_time(record.log_time), None, "")
        if replacing is not None:
            kind, summary = EventKind.MISSION_REPLACED, str(replacing.message.summary)
            info = Revision(revision, self._next_time(replacing.log_time), kind, summary)
        content, _ = mission_from_msg(record.message)
        self._mission = _state(content, revision)
        self._entries.append(_Entry(info, None, content))
        self._timeline.reset(self._mission, info.log_time)
        self._since_checkpoint = 0

    def _apply(self, record: JournalRecord) -> bool:
        """Apply the next event; False (and a problem) if it does not apply."""
        mission = self._mission
        assert mission is not None
        revision = int(record.message.revision)
        try:
            event = event_from_msg(record.message)
            self._timeline.event(mission, event, record.log_time)
            apply_event(mission, event)
        except RosmcError as err:
            self._problems.append(f"revision {revision} does not apply ({err}); skipped")
            return False
        self._since_checkpoint += 1
        checkpoint = None
        if self._since_checkpoint >= CHECKPOINT_EVERY:
            checkpoint, self._since_checkpoint = mission.content(), 0
        info = Revision(revision, self._next_time(record.log_time), event.kind, event.summary)
        self._entries.append(_Entry(info, event if checkpoint is None else None, checkpoint))
        return True

    def _next_time(self, log_time: int) -> int:
        """``log_time``, or the previous revision's if later: an event journaled before a
        late snapshot is shown right after it, so times never go back."""
        return max(log_time, self._entries[-1].info.log_time) if self._entries else log_time


def _state(content: MissionContent | None, revision: int) -> MissionState:
    """A mission state to apply events on (applying needs no library)."""
    assert content is not None
    return MissionState(content, revision)
