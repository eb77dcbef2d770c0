"""Reading a mission journal back, including one whose writer was killed mid-write."""

import logging
from collections.abc import Collection
from dataclasses import dataclass
from pathlib import Path

from rosmc_server.interface import EVENTS_TOPIC, MISSION_TOPIC
from rosmc_server.recording import _scan
from rosmc_server.recording._codec import Decoder, RosMessage
from rosmc_server.recording.errors import JournalError

_log = logging.getLogger(__name__)


@dataclass(frozen=True)
class JournalRecord:
    """One recorded message: its topic, log time (ns) and the decoded genpy message."""

    topic: str
    log_time: int
    message: RosMessage


@dataclass(frozen=True)
class JournalResult:
    """Everything recovered from a journal file.

    Attributes:
        path: The file that was read.
        records: Every intact message in file order.
        dropped_bytes: Bytes at the end that were not used: a record cut short, a damaged
            record and everything after it, or an unfinished summary. 0 for a clean file.
        complete: Whether the file ended with a footer (its writer closed it).
        warnings: One sentence per problem found, each naming the file.
    """

    path: Path
    records: tuple[JournalRecord, ...]
    dropped_bytes: int
    complete: bool
    warnings: tuple[str, ...]

    @property
    def clean(self) -> bool:
        """True for a closed journal read without any problem."""
        return self.complete and not self.warnings

    def messages(self, topic: str) -> list[RosMessage]:
        """Return the messages recorded on ``topic``, in file order."""
        return [r.message for r in self.records if r.topic == topic]


@dataclass(frozen=True)
class LatestState:
    """The last mission snapshot of a journal and the events recorded after it.

    Attributes:
        snapshot: The last ``rosmc/Mission`` snapshot.
        snapshot_time: Its log time (ns).
        events: The ``rosmc/MissionEvent`` messages after it with a higher revision, in order.
        problems: Error-level findings (missing revisions, a replaced mission without its
            snapshot); a state with problems is not a faithful copy of the last mission.
        notes: What was left out on purpose (a change recorded but never acknowledged).
    """

    snapshot: RosMessage
    snapshot_time: int
    events: tuple[RosMessage, ...]
    problems: tuple[str, ...]
    notes: tuple[str, ...] = ()

    @property
    def revision(self) -> int:
        """The revision the mission reaches once the events are applied to the snapshot."""
        return int(self.events[-1].revision if self.events else self.snapshot.revision)


def read_journal(path: str | Path, topics: Collection[str] | None = None) -> JournalResult:
    """Read every intact record of a journal, closed or not, and say what was lost.

    Args:
        path: The ``.mcap`` journal.
        topics: Decode only the records of these topics (all if None).

    Raises:
        JournalError: The file is missing, empty, not MCAP, or ends before its header.
    """
    return decode_scan(_scan.scan(Path(path)), topics)


def decode_scan(scan: _scan.ScanResult, topics: Collection[str] | None = None) -> JournalResult:
    """Decode the messages a scan found into a JournalResult and log its warnings."""
    decoder = Decoder()
    records: list[JournalRecord] = []
    failures: dict[str, list[str]] = {}
    for msg in scan.messages:
        channel = scan.channels[msg.channel_id]
        if topics is not None and channel.topic not in topics:
            continue
        schema = scan.schemas.get(channel.schema_id)
        try:
            if schema is None:
                raise JournalError("its channel has no schema")
            records.append(
                JournalRecord(channel.topic, msg.log_time, decoder.decode(schema, msg.data))
            )
        except JournalError as err:
            failures.setdefault(channel.topic, []).append(str(err))
    warnings = list(scan.warnings)
    warnings += [f"journal {scan.path}: {note}" for note in decoder.notes]
    for topic, reasons in failures.items():
        warnings.append(
            f"journal {scan.path}: skipped {len(reasons)} intact records on {topic} that do not "
            f"decode (first: {reasons[0]})"
        )
    for text in warnings:
        _log.warning("%s", text)
    return JournalResult(
        scan.path, tuple(records), scan.dropped_bytes, scan.complete, tuple(warnings)
    )


def latest_state(result: JournalResult) -> LatestState:
    """Pick the newest snapshot and the events after it, to rebuild the mission from.

    Events at or below the snapshot's revision are already part of it and left out.
    A missing revision, a revision that goes backwards, or a mission replacement
    whose snapshot is missing is reported in ``problems`` and logged as an error.

    A ``MISSION_REPLACED`` event carries no content, so the writer must append the new
    mission's snapshot right after it and acknowledge the change only then. A journal
    that *ends* with such an event lost that snapshot before the change was
    acknowledged: the event is left out (and said so in ``notes``).

    Raises:
        JournalError: The journal holds no snapshot.
    """
    last = None
    for index, record in enumerate(result.records):
        # The newest snapshot by revision: a periodic one built off the service path
        # can land in the file after a newer one (e.g. after a mission replacement).
        if record.topic == MISSION_TOPIC and (
            last is None
            or int(record.message.revision) >= int(result.records[last].message.revision)
        ):
            last = index
    if last is None:
        raise JournalError(f"journal {result.path} holds no mission snapshot to start from")
    snapshot = result.records[last]
    expected = int(snapshot.message.revision) + 1
    events: list[RosMessage] = []
    problems: list[str] = []
    # A periodic snapshot may be written a moment after the events that followed the
    # revision it shows (the server builds it off the service path), so events with a
    # higher revision count wherever they stand in the file.
    after = int(snapshot.message.revision)
    tail = [
        r.message
        for r in result.records
        if r.topic == EVENTS_TOPIC and int(r.message.revision) > after
    ]
    notes: list[str] = []
    if tail and tail[-1].kind == tail[-1].MISSION_REPLACED:
        notes.append(
            f"revision {tail.pop().revision} replaced the mission, but the journal ends before "
            "the new mission's snapshot: that change was never acknowledged and is left out"
        )
    for event in tail:
        revision = int(event.revision)
        if revision < expected:
            if events:  # only a repeat *after* the snapshot is suspicious
                problems.append(f"event revision {revision} repeats or goes backwards; ignored")
            continue
        if revision > expected:
            missing = f"{expected}" if revision == expected + 1 else f"{expected} to {revision - 1}"
            problems.append(f"revision {missing} is missing before revision {revision}")
        if event.kind == event.MISSION_REPLACED:
            problems.append(
                f"revision {revision} replaced the mission but no snapshot of the new mission "
                "follows it"
            )
        events.append(event)
        expected = revision + 1
    problems = [f"journal {result.path}: {text}" for text in problems]
    notes = [f"journal {result.path}: {text}" for text in notes]
    for text in problems:
        _log.error("%s", text)
    for text in notes:
        _log.warning("%s", text)
    return LatestState(
        snapshot.message, snapshot.log_time, tuple(events), tuple(problems), tuple(notes)
    )
