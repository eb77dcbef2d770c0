"""The mission at every revision of a journal, for people reviewing what happened.

:class:`MissionHistory` reads a journal's records once, without decoding them: it
follows the revisions from the first snapshot (starting over from the snapshot that
follows a ``MISSION_REPLACED`` event, which carries no content) and notes, per
revision, its time, kind and summary (read from the event's bytes) and any snapshot
of it. The mission at a revision is rebuilt when asked for, from the nearest
snapshot at or before it and the events after it (:mod:`.history_states`), so
``rosmc at``, a replay's seek and ``rosmc info`` cost one snapshot and a few hundred
events, not the whole recording. The timeline, which needs every event, is built on
the first call of :meth:`MissionHistory.timeline`. Times are seconds since the
recording started (its first record) unless a log time (ns) is asked for.

Typical use::

    history = MissionHistory.from_journal("bags/mission_20260101_120000.mcap")
    state = history.at_time(42.0)  # a MissionState
    lanes = history.timeline().lanes
"""

from __future__ import annotations

import bisect
from dataclasses import dataclass
from pathlib import Path

from rosmc_server.conversions import event_from_msg
from rosmc_server.core import (
    EventKind,
    InvalidRequest,
    MissionState,
    NotFound,
    RosmcError,
)
from rosmc_server.core.live.updates import apply_event
from rosmc_server.interface import EVENTS_TOPIC, MISSION_TOPIC, ROBOT_REPORTS_TOPIC
from rosmc_server.recording.damage import skipped_line
from rosmc_server.recording.errors import JournalError
from rosmc_server.recording.history_states import (
    CHECKPOINT_EVERY,
    StateBuilder,
    Step,
    snapshot_content,
)
from rosmc_server.recording.reader import JournalRecord, JournalResult, feed, read_journal
from rosmc_server.recording.revisions import Gap, RevisionWalk
from rosmc_server.recording.timeline import Timeline, TimelineBuilder

__all__ = ["CHECKPOINT_EVERY", "MissionHistory", "Revision"]


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


class MissionHistory:
    """Every revision of the mission a journal holds; build it with :meth:`from_journal`."""

    def __init__(self, result: JournalResult, start: int | None = None) -> None:
        """Index ``result`` (a read journal); raises JournalError without a snapshot.

        ``start``: time 0 of the recording (log time, ns) when ``result`` holds only some
        of its part files (see :mod:`.moments`); by default its first record's.
        """
        self.path = result.path
        self.warnings: tuple[str, ...] = result.warnings
        """What reading the file found wrong (a cut-off tail, undecodable records)."""
        if not result.records:
            raise JournalError(f"journal {result.path} holds no records")
        self.start = min(record.log_time for record in result.records) if start is None else start
        """Log time (ns) of the first record: time 0 of the recording."""
        self.end = max(record.log_time for record in result.records)
        """Log time (ns) of the last record."""
        topics = (MISSION_TOPIC, EVENTS_TOPIC, ROBOT_REPORTS_TOPIC)
        self._records = tuple(r for r in result.records if r.topic in topics)
        self._infos: list[Revision] = []
        self._steps: list[Step] = []
        self._problems: list[str] = []
        self._timeline: Timeline | None = None
        self.gaps: tuple[Gap, ...] = ()
        """The revisions that cannot be rebuilt (damaged or missing records)."""
        self.damage = result.damage
        """The damaged byte ranges reading skipped."""
        self._index()
        skipped = skipped_line(self.path, self.damage, self.gaps)
        self._skipped: tuple[str, ...] = (skipped,) if skipped else ()
        self._revisions = [info.revision for info in self._infos]
        self._times = [info.log_time for info in self._infos]
        self._builder = StateBuilder(self._steps, self._problems.append)

    @classmethod
    def from_journal(cls, path: str | Path) -> MissionHistory:
        """Read and index the journal at ``path``.

        Raises:
            JournalError: The file is not a readable journal or holds no snapshot.
        """
        return cls(read_journal(path, (MISSION_TOPIC, EVENTS_TOPIC, ROBOT_REPORTS_TOPIC)))

    # -- queries ---------------------------------------------------------------------
    @property
    def problems(self) -> tuple[str, ...]:
        """What was skipped (one line: damaged bytes and the revisions they cost) and any
        other revision that could not be rebuilt, one sentence each (empty when intact).

        An event that does not apply is found once a state that needs it is built (the
        timeline builds every one).
        """
        return self._skipped + tuple(f"journal {self.path}: {text}" for text in self._problems)

    @property
    def revisions(self) -> tuple[Revision, ...]:
        """Every revision the history can show, oldest first."""
        return tuple(self._infos)

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
            NotFound: The recording does not hold that revision (or cannot rebuild it).
        """
        index = bisect.bisect_left(self._revisions, revision)
        if index == len(self._revisions) or self._revisions[index] != revision:
            raise NotFound(
                f"journal {self.path} holds no revision {revision} (it holds "
                f"{self._revisions[0]} to {self._revisions[-1]}"
                + (", with gaps)" if self.problems else ")")
            )
        return self._builder.state(index)

    def at_time(self, t: float, *, log_time: bool = False) -> MissionState:
        """The mission as it was at ``t`` seconds since the start (or at log time ``t`` ns).

        The mission before the first snapshot is that snapshot; after the last
        record, the last revision.

        Raises:
            InvalidRequest: ``t`` is negative (or not a number).
        """
        if not t >= 0:
            raise InvalidRequest(f"a time must be 0 or more, got {t}")
        index = self._index_of(int(t) if log_time else self._log_time(t))
        return self._builder.state(index)

    def revision_at(self, t: float) -> Revision:
        """The revision current ``t`` seconds after the start."""
        return self._infos[self._index_of(self._log_time(max(t, 0.0)))]

    def timeline(self) -> Timeline:
        """Every robot's skill executions, barrier waits and barrier releases."""
        if self._timeline is None:
            self._timeline = _timeline(self, self._records)
        return self._timeline

    # -- indexing --------------------------------------------------------------------
    def _log_time(self, seconds: float) -> int:
        return self.start + round(seconds * 1e9)

    def _index_of(self, log_time: int) -> int:
        """The last revision journaled at or before ``log_time`` (the first if none was)."""
        return max(0, bisect.bisect_right(self._times, log_time) - 1)

    def _index(self) -> None:
        """Follow the revisions through the records, decoding none of them."""
        walk: RevisionWalk[JournalRecord, JournalRecord] = RevisionWalk(
            self._restart, self._apply, self._covered
        )
        for record in self._records:
            if record.topic != ROBOT_REPORTS_TOPIC:
                feed(walk, record)
        walk.finish()
        if walk.unacknowledged is not None:
            self._problems.append(
                f"revision {walk.unacknowledged} replaced the mission, but the journal ends "
                "before the new mission's snapshot; it is left out"
            )
        self.gaps = tuple(walk.gaps)
        if not self._infos:
            raise JournalError(f"journal {self.path} holds no mission snapshot to start from")

    def _restart(self, record: JournalRecord, replacing: JournalRecord | None) -> None:
        """(Re)start the history from a snapshot (of a replacement, if given)."""
        revision = record.revision
        info = Revision(revision, self._next_time(record.log_time), None, "")
        if replacing is not None:
            kind, summary = EventKind.MISSION_REPLACED, str(replacing.field("summary"))
            info = Revision(revision, self._next_time(replacing.log_time), kind, summary)
        self._infos.append(info)
        self._steps.append(Step(revision, None, record))

    def _apply(self, record: JournalRecord) -> bool:
        """Take the next event; False (and a problem) if it is not a change the core knows."""
        revision = record.revision
        try:
            kind = EventKind(record.kind)
        except ValueError:
            try:  # as a full decode says it
                event_from_msg(record.message)
                reason = f"kind {record.kind} is unknown"
            except RosmcError as err:
                reason = str(err)
            self._problems.append(f"revision {revision} does not apply ({reason}); skipped")
            return False
        summary = str(record.field("summary"))
        self._infos.append(Revision(revision, self._next_time(record.log_time), kind, summary))
        self._steps.append(Step(revision, record))
        return True

    def _covered(self, record: JournalRecord) -> None:
        """A periodic snapshot of a revision reached already: a place to rebuild from."""
        index = bisect.bisect_left(self._steps, record.revision, key=_revision)
        found = self._steps[index] if index < len(self._steps) else None
        if found is not None and found.revision == record.revision and found.snapshot is None:
            found.snapshot = record

    def _next_time(self, log_time: int) -> int:
        """``log_time``, or the previous revision's if later: an event journaled before a
        late snapshot is shown right after it, so times never go back."""
        return max(log_time, self._infos[-1].log_time) if self._infos else log_time


def _revision(step: Step) -> int:
    return step.revision


def _timeline(history: MissionHistory, records: tuple[JournalRecord, ...]) -> Timeline:
    """The timeline of every event and robot report, applied one after the other."""
    builder = TimelineBuilder(history.start)
    mission: list[MissionState] = []

    def restart(record: JournalRecord, replacing: JournalRecord | None) -> None:
        log_time = record.log_time if replacing is None else replacing.log_time
        mission[:] = [MissionState(snapshot_content(record), record.revision)]
        builder.reset(mission[0], log_time)

    def apply(record: JournalRecord) -> bool:
        try:
            event = event_from_msg(record.message)
            builder.event(mission[0], event, record.log_time)
            apply_event(mission[0], event, describe=False)
        except RosmcError:
            return False
        return True

    walk: RevisionWalk[JournalRecord, JournalRecord] = RevisionWalk(restart, apply)
    for record in records:
        if record.topic == ROBOT_REPORTS_TOPIC:
            builder.report(record.message, record.log_time)
        else:
            feed(walk, record)
    walk.finish()
    return builder.build(history.duration)
