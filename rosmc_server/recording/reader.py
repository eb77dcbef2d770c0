"""Reading a mission journal back, including one whose writer was killed mid-write."""

import logging
from collections.abc import Collection, Sequence
from dataclasses import dataclass, replace
from pathlib import Path

from rosmc_server.interface import EVENTS_TOPIC, MISSION_TOPIC
from rosmc_server.recording._mcap import scan as _scan
from rosmc_server.recording._mcap.codec import Decoder, RosMessage, is_installed
from rosmc_server.recording._mcap.files import journal_parts
from rosmc_server.recording.channels import LIBRARY
from rosmc_server.recording.damage import Damage
from rosmc_server.recording.errors import JournalError
from rosmc_server.recording.lazy import JournalRecord, Leads, Payload
from rosmc_server.recording.revisions import Gap, RevisionWalk

__all__ = [
    "JournalRecord",
    "JournalResult",
    "LatestState",
    "decode_scan",
    "feed",
    "join_results",
    "latest_state",
    "read_journal",
]

_log = logging.getLogger(__name__)

MISSION_REPLACED = 19
"""``rosmc/MissionEvent.MISSION_REPLACED`` (a constant of the message, fixed for good)."""


@dataclass(frozen=True)
class JournalResult:
    """Everything recovered from a journal (all its part files, or one file).

    Attributes:
        path: The journal that was read (its first file).
        records: Every intact message in file order.
        dropped_bytes: Bytes at the end that were not used: a record cut short, damage
            that runs to the end, or an unfinished summary. 0 for a clean file.
        complete: Whether every file ended with a footer (its writer closed it).
        warnings: One sentence per problem found other than damage, each naming the file.
        damage: The damaged byte ranges that were skipped (see :func:`.skipped_line`).
        files: The files read, in order.
    """

    path: Path
    records: tuple[JournalRecord, ...]
    dropped_bytes: int
    complete: bool
    warnings: tuple[str, ...]
    damage: tuple[Damage, ...] = ()
    files: tuple[Path, ...] = ()

    @property
    def clean(self) -> bool:
        """True for a closed journal read without any problem."""
        return self.complete and not self.warnings and not self.damage

    @property
    def size(self) -> int:
        """Bytes of all the files read."""
        return sum(file.stat().st_size for file in self.files if file.exists())

    def messages(self, topic: str) -> list[RosMessage]:
        """Return the messages recorded on ``topic``, in file order."""
        return [r.message for r in self.records if r.topic == topic]


@dataclass(frozen=True)
class LatestState:
    """The snapshot and events to rebuild the newest mission a journal holds.

    Attributes:
        snapshot: The ``rosmc/Mission`` snapshot to start from.
        snapshot_time: Its log time (ns).
        events: The ``rosmc/MissionEvent`` messages to apply on it, in order.
        problems: Error-level findings, one sentence each (revisions that cannot be
            rebuilt); a state with problems is not a faithful copy of the last mission.
        notes: What was left out on purpose (a change recorded but never acknowledged).
        gaps: The revisions that cannot be rebuilt (see :attr:`lost`).
        highest: The highest revision the journal holds (-1 for none).
        unacknowledged: The revision of a replacement the journal ends with before its
            snapshot (left out), or None.
    """

    snapshot: RosMessage
    snapshot_time: int
    events: tuple[RosMessage, ...]
    problems: tuple[str, ...]
    notes: tuple[str, ...] = ()
    gaps: tuple[Gap, ...] = ()
    highest: int = -1
    unacknowledged: int | None = None

    @property
    def revision(self) -> int:
        """The revision the mission reaches once the events are applied to the snapshot."""
        return int(self.events[-1].revision if self.events else self.snapshot.revision)

    @property
    def lost(self) -> Gap | None:
        """Recorded revisions that are not in the rebuilt mission: no snapshot follows them."""
        last = self.gaps[-1] if self.gaps else None
        return last if last is not None and last.resumed_at is None else None

    @property
    def next_revision(self) -> int:
        """The revision the next change must get: above every revision the journal holds."""
        return max(self.revision, self.highest) + 1


def read_journal(path: str | Path, topics: Collection[str] | None = None) -> JournalResult:
    """Read every intact record of a journal, closed or not, and say what was lost.

    A journal that grew past one file is read whole: ``path`` names its first file
    (or any part) and every part follows in order.

    Args:
        path: The ``.mcap`` journal.
        topics: Decode only the records of these topics (all if None).

    Raises:
        JournalError: The file is missing, empty, not MCAP, or ends before its header.
    """
    base, parts = journal_parts(path)
    results = [decode_scan(_scan.scan(parts[0][1]), topics)]
    warnings: list[str] = []
    expected = parts[0][0] + 1
    for number, part in parts[1:]:
        if number != expected:
            missing = f"{expected}" if number == expected + 1 else f"{expected} to {number - 1}"
            warnings.append(f"journal {base}: part {missing} is missing")
        expected = number + 1
        try:
            results.append(decode_scan(_scan.scan(part), topics))
        except JournalError as err:  # e.g. a part created just before a crash
            warnings.append(f"skipped {part.name}: {err}")
    for text in warnings:
        _log.warning("%s", text)
    return join_results(base, results, warnings)


def join_results(
    path: Path, results: Sequence[JournalResult], warnings: Sequence[str] = ()
) -> JournalResult:
    """One result of the parts of a journal read one by one, in order."""
    if len(results) == 1 and not warnings:
        return replace(results[0], path=path)
    return JournalResult(
        path,
        tuple(record for result in results for record in result.records),
        sum(result.dropped_bytes for result in results),
        all(result.complete for result in results),
        tuple(w for result in results for w in result.warnings) + tuple(warnings),
        tuple(d for result in results for d in result.damage),
        tuple(f for result in results for f in result.files),
    )


def decode_scan(scan: _scan.ScanResult, topics: Collection[str] | None = None) -> JournalResult:
    """Decode the messages a scan found into a JournalResult and log its warnings.

    Damage is not logged here: whoever reads the journal reports it in one line (with
    the revisions it cost, which only they know).

    The messages of a chunked journal, which the chunks' CRCs vouch for, are decoded on
    first use (see :mod:`.lazy`), but for the first of each schema: a definition that
    cannot decode is found here (not with a big payload, a snapshot, of a schema that is
    the installed definition: decoding a 10,000-skill snapshot costs genpy 0.2 s, and
    the generated class decodes what it serialized). Every other file's messages are
    decoded here, as a bare message that does not decode is damage; a big one is not
    kept decoded.
    """
    decoder = Decoder()
    leads = Leads()
    records: list[JournalRecord] = []
    failures: dict[str, list[str]] = {}
    damage = list(scan.damage)
    lazy = scan.library == LIBRARY and bool(scan.chunk_indexes)
    tried: set[int] = set()  # schemas one message of which was decoded
    installed = {schema.id: is_installed(schema) for schema in scan.schemas.values()}
    for msg, (start, end) in zip(scan.messages, scan.spans, strict=True):
        channel = scan.channels[msg.channel_id]
        if topics is not None and channel.topic not in topics:
            continue
        schema = scan.schemas.get(channel.schema_id)
        try:
            if schema is None:
                raise JournalError("its channel has no schema")
            payload = Payload(decoder, schema, msg, leads.of(schema))
            message = None
            trusted = payload.big and installed.get(schema.id, False)
            if not lazy or (schema.id not in tried and not trusted):
                message = payload.decode()
                tried.add(schema.id)
            keep = None if payload.big else message
            records.append(JournalRecord(channel.topic, msg.log_time, keep, payload))
        except JournalError as err:
            # A journal's bare message (no CRC) that does not decode: its bytes are damaged.
            if schema is not None and scan.library == LIBRARY and not scan.chunk_indexes:
                what = f"a {schema.name} message that does not decode"
                damage.append(Damage(scan.path, start, end, what))
            else:
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
        scan.path,
        tuple(records),
        scan.dropped_bytes,
        scan.complete,
        tuple(warnings),
        tuple(sorted(damage, key=lambda d: d.start)),
        (scan.path,),
    )


def latest_state(result: JournalResult) -> LatestState:
    """Pick the snapshot and the events to rebuild the newest mission from.

    The mission starts from the newest snapshot that the events before it reach (or
    that a gap makes necessary) and takes every event that follows it one by one;
    events journaled before a late periodic snapshot count too. A missing revision (a
    damaged record) stops the events: what follows it is in :attr:`LatestState.gaps`
    and, if no snapshot follows, in :attr:`LatestState.lost`.

    A ``MISSION_REPLACED`` event carries no content, so the writer must append the new
    mission's snapshot right after it and acknowledge the change only then. A journal
    that *ends* with such an event lost that snapshot before the change was
    acknowledged: the event is left out (and said so in ``notes``).

    Raises:
        JournalError: The journal holds no snapshot.
    """
    base: list[JournalRecord] = []
    events: list[JournalRecord] = []  # decoded at the end: only those after the base

    def restart(snapshot: JournalRecord, _replacing: JournalRecord | None) -> None:
        base[:] = [snapshot]
        events.clear()

    def apply(event: JournalRecord) -> bool:
        events.append(event)
        return True

    def covered(snapshot: JournalRecord) -> None:
        # A newer periodic snapshot saves replaying the events it already holds.
        revision = snapshot.revision
        if base and revision >= base[0].revision:
            base[:] = [snapshot]
            events[:] = [e for e in events if e.revision > revision]

    walk: RevisionWalk[JournalRecord, JournalRecord] = RevisionWalk(restart, apply, covered)
    for record in result.records:
        feed(walk, record)
    walk.finish()
    if not base:
        raise JournalError(f"journal {result.path} holds no mission snapshot to start from")
    notes = []
    if walk.unacknowledged is not None:
        notes.append(
            f"journal {result.path}: revision {walk.unacknowledged} replaced the mission, but "
            "the journal ends before the new mission's snapshot: that change was never "
            "acknowledged and is left out"
        )
    return LatestState(
        base[0].message,
        base[0].log_time,
        tuple(event.message for event in events),
        tuple(f"journal {result.path}: {gap}" for gap in walk.gaps),
        tuple(notes),
        tuple(walk.gaps),
        walk.highest,
        walk.unacknowledged,
    )


def feed(walk: RevisionWalk[JournalRecord, JournalRecord], record: JournalRecord) -> None:
    """Hand a snapshot or event record to ``walk``; records of other topics are ignored."""
    if record.topic == MISSION_TOPIC:
        walk.snapshot(record.revision, record)
    elif record.topic == EVENTS_TOPIC:
        walk.event(record.revision, record.kind == MISSION_REPLACED, record)
