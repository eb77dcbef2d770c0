"""The mission's journal as the server keeps it: opened or resumed, one record per change.

This is where the journal's promises are kept, for the server and for the crash-point
tests alike (they drive this class with a real mission, then cut its files at every
record and resume them):

* **A change is answered only once its whole record is durable.** :meth:`MissionJournal.
  record` returns after the event (and, for a change that replaces the mission, its
  snapshot) is written and synced; the caller publishes and answers only then. If it
  raises, the change must not be shown to anyone: the server stops serving.
* **A change that replaces the mission is one unit**: its event and the new mission's
  snapshot are one chunk (:meth:`JournalWriter.append_replacement`).
* **A resume that drops an unfinished record removes it first** (:mod:`._mcap.reopen`
  cuts a torn tail or a replacement's lone event off the file before appending); a last
  file with damage stays as it is and the journal goes on in a new part file, which
  starts with a snapshot of where the mission resumed.
* **A revision number never names two missions**: the revision mark is kept in a side
  file and in the journal's head (:mod:`.mark_recovery`); after lost revisions, an
  unfinished replacement left in a damaged file, or a lost mark, the resumed mission
  takes a revision of its own above every number that may have gone out, in a new epoch.
"""

from __future__ import annotations

import dataclasses
import logging
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

from rosmc_server.conversions import event_from_msg, mission_from_msg, mission_to_msg
from rosmc_server.conversions.event_packing import packed_event
from rosmc_server.conversions.request_fields import FIRST_REVISION
from rosmc_server.core import Library, Mission, MissionContent, MissionEvent
from rosmc_server.core.model.changes import EventKind
from rosmc_server.recording._mcap.codec import RosMessage
from rosmc_server.recording._mcap.files import journal_parts
from rosmc_server.recording.high_water import RevisionMark, first_mark, resumed_mark
from rosmc_server.recording.journal_options import JournalOptions
from rosmc_server.recording.mark_recovery import recover_mark
from rosmc_server.recording.reader import latest_state
from rosmc_server.recording.recovery import ResumeReport
from rosmc_server.recording.writer import JournalWriter

_log = logging.getLogger(__name__)

SnapshotOf = Callable[[Mission], RosMessage]
"""The ``rosmc/Mission`` snapshot of a mission (the server passes its cached packer)."""


@dataclass(frozen=True)
class Resumed:
    """A resumed journal and the mission it holds.

    Attributes:
        journal: The journal, open to go on.
        mission: The mission at the last acknowledged revision (or at a revision of its
            own above every number that may have gone out, after a loss).
        report: What the resume could not recover (see :class:`ResumeReport`).
    """

    journal: MissionJournal
    mission: Mission
    report: ResumeReport


class MissionJournal:
    """A journal being written and its revision mark. Not thread-safe: the server's lock
    serialises :meth:`record`; telemetry goes to :attr:`writer` directly (it has its own)."""

    def __init__(self, writer: JournalWriter, marks: RevisionMark) -> None:
        """Wrap an open writer and mark; use :meth:`create` or :meth:`resume`."""
        self.writer = writer
        self.marks = marks

    @classmethod
    def create(
        cls,
        path: Path,
        mission: Mission,
        options: JournalOptions,
        library: RosMessage | None = None,
    ) -> MissionJournal:
        """Start a new journal at ``path`` with a snapshot of ``mission``."""
        snapshot = mission_to_msg(mission.state.content(), mission.revision, time.time())
        writer = JournalWriter.create(path, snapshot, time.time_ns(), options, library)
        marks = RevisionMark(path, first_mark(mission.revision), options.fsync, writer.write_mark)
        return cls(writer, marks)

    @classmethod
    def resume(
        cls,
        path: Path,
        library: Library,
        options: JournalOptions,
        library_msg: RosMessage | None = None,
        clock: Callable[[], float] = time.time,
    ) -> Resumed:
        """Recover the journal at ``path`` and the newest mission it holds; say once, loudly,
        what could not be recovered.

        Raises:
            JournalError: The journal is missing, locked or holds no snapshot to start from.
        """
        writer = JournalWriter.resume(path, options, library_msg)
        assert writer.recovered is not None
        latest = latest_state(writer.recovered)
        for note in latest.notes:
            _log.warning("%s", note)
        content, revision = mission_from_msg(latest.snapshot)
        mission = Mission(library, content, revision, clock=clock)
        for event_msg in latest.events:
            mission.replay(event_from_msg(event_msg))
        recovered = recover_mark(writer.path, [file for _, file in journal_parts(writer.path)[1]])
        report = ResumeReport.of(
            writer.path, writer.recovered.damage, latest, writer.part_path, recovered
        )
        if report.lost and not writer.damaged:  # later resumes start after the loss
            writer.start_next_part()
            report = dataclasses.replace(report, written_to=writer.part_path)
        if report.alert():
            _log.error("%s", report.log_line())
        own = _own_revision(report, latest.unacknowledged)
        if own > mission.revision:  # a revision of its own: views holding the lost are stale
            mission = Mission(library, mission.state.content(), own, clock=clock)
        marked = resumed_mark(recovered.mark, mission.revision, report.history_lost)
        marks = RevisionMark(writer.path, marked, options.fsync, writer.write_mark)
        journal = cls(writer, marks)
        if writer.needs_snapshot or not report.clean or own > revision:
            writer.append_snapshot(
                mission_to_msg(mission.state.content(), mission.revision, clock()), time.time_ns()
            )
        _log.info("resumed from %s at revision %d", writer.path, mission.revision)
        return Resumed(journal, mission, report)

    @property
    def epoch(self) -> str:
        """The mission's history: new whenever a resume lost history."""
        return self.marks.epoch

    @property
    def path(self) -> Path:
        """The journal (its first file)."""
        return self.writer.path

    def record(self, event: MissionEvent, mission: Mission, snapshot: SnapshotOf) -> RosMessage:
        """Journal an accepted change of ``mission`` (already applied); durable on return.

        Returns the event's message, to publish (only now: it is durable). A change that
        replaces the mission is written with ``snapshot(mission)`` as one unit.

        Raises:
            JournalError, OSError: Nothing may show the change: it is not durable.
        """
        state = mission.state
        msg = packed_event(event, lambda skill_id: state.locate(skill_id)[0], self.epoch)
        stamp_ns = time.time_ns()
        if event.kind is EventKind.MISSION_REPLACED:
            self.writer.append_replacement(msg, snapshot(mission), stamp_ns)
        else:
            self.writer.append_event(msg, stamp_ns)
        self.marks.record(event.revision)  # after the record: the mark names only what is down
        return msg

    def close(self) -> None:
        """Close the journal (a complete MCAP file) and its mark."""
        if not self.writer.closed:
            self.writer.close()
        self.marks.close()

    @staticmethod
    def new_mission(library: Library, clock: Callable[[], float] = time.time) -> Mission:
        """An empty mission at :data:`FIRST_REVISION`, to start a new journal with."""
        return Mission(library, MissionContent.empty(library), FIRST_REVISION, clock=clock)


def _own_revision(report: ResumeReport, unacknowledged: int | None) -> int:
    """The revision the resumed mission takes: above every number that may have gone out.

    After lost revisions or a lost mark, the next one the report names; after a
    replacement left unfinished in a damaged file (not cut off), that replacement's
    number, so that the snapshot the resume writes completes it with the mission as it
    stood and no later change follows a replacement without content.
    """
    own = report.next_revision - (0 if report.history_lost else 1)
    if unacknowledged is not None:
        own = max(own, unacknowledged)
    return own
