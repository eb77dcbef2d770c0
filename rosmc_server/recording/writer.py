"""Appending accepted mission changes to an MCAP journal, durably, one write per change."""

import logging
import threading
from collections.abc import Mapping
from pathlib import Path
from types import TracebackType
from typing import Self

from rosmc_server.core.errors import StorageFull
from rosmc_server.interface import (
    AGENT_STATES_TOPIC,
    EVENTS_TOPIC,
    LIBRARY_TOPIC,
    MISSION_TOPIC,
    ROBOT_COMMANDS_TOPIC,
    ROBOT_REPORTS_TOPIC,
)
from rosmc_server.recording._mcap import records as fmt
from rosmc_server.recording._mcap.codec import RosMessage, serialize
from rosmc_server.recording._mcap.files import journal_parts
from rosmc_server.recording._mcap.reopen import reopen
from rosmc_server.recording._mcap.write import PartFile
from rosmc_server.recording.channels import JOURNAL_TOPICS, TELEMETRY_TOPICS
from rosmc_server.recording.errors import JournalError
from rosmc_server.recording.journal_options import DEFAULT_OPTIONS, JournalOptions
from rosmc_server.recording.part_series import PartSeries
from rosmc_server.recording.reader import JournalResult
from rosmc_server.recording.space import DiskSpace

_log = logging.getLogger(__name__)


class JournalWriter:
    """Appends mission events, snapshots and telemetry to a journal.

    Every append reaches the operating system in a single ``write`` before it returns
    (and the disk, with ``fsync``), so a change acknowledged after ``append_event``
    survives a crash of the process. ``close`` adds the summary that makes the file a
    complete, indexed MCAP file. Telemetry is skipped, and robot reports refused, near a
    full disk (:mod:`.space`); ask :meth:`require_space` before applying a change. A
    journal that grows past ``part_bytes`` goes on in part files beside the first
    (:mod:`.part_series`). Open one with :meth:`create` or :meth:`resume`. Thread-safe:
    appends from several threads are written one after the other. An advisory file
    lock keeps a second writer (in any process) off the same file.
    """

    def __init__(
        self,
        base: Path,
        part: PartFile,
        options: JournalOptions,
        recovered: JournalResult | None = None,
        damaged: bool = False,
        library: RosMessage | None = None,
    ) -> None:
        """Wrap an open part file; use create or resume instead."""
        self._base = base
        self._library = library
        self._library_part = 0  # the part file the library was last written to
        self._files = PartSeries(base, part, options)
        self._options = options
        self._events_since_snapshot = 0
        self._telemetry_skipped = False
        self._newest_revision = -1  # of any event or snapshot written
        self._lock = threading.RLock()
        self.space = DiskSpace(part.path.parent, options.reserve_bytes)
        """The free space of the journal's disk."""
        self.recovered = recovered
        """What resume recovered from the journal (None for a new journal)."""
        self.damaged = damaged
        """Resume found damage in the last file and went on in a new part file."""

    @classmethod
    def create(
        cls,
        path: str | Path,
        snapshot: RosMessage,
        log_time_ns: int,
        options: JournalOptions = DEFAULT_OPTIONS,
        library: RosMessage | None = None,
    ) -> "JournalWriter":
        """Start a new journal that opens with ``snapshot``; never overwrites a file.

        ``library`` (``rosmc/Library``), the library the server runs with, follows the first
        snapshot of every part file, so that a replay shows the recording with it.

        Raises:
            JournalError: The file (or a part file of that name) exists or cannot be written.
        """
        path = Path(path)
        _, parts = journal_parts(path)
        if len(parts) > 1:
            raise JournalError(
                f"cannot open journal {path}: part files of an older journal of that name "
                f"exist ({parts[1][1].name})"
            )
        part = PartFile.create(path, 1, options.chunked, options.fsync)
        writer = cls(path, part, options, library=library)
        try:
            writer.append_snapshot(snapshot, log_time_ns)
        except JournalError:
            writer.abandon()
            path.unlink()  # it holds nothing anybody was told about
            raise
        return writer

    @classmethod
    def resume(
        cls,
        path: str | Path,
        options: JournalOptions = DEFAULT_OPTIONS,
        library: RosMessage | None = None,
    ) -> "JournalWriter":
        """Recover a journal and continue it (``library``: as for :meth:`create`, written
        with the next snapshot).

        Reads the journal's last file (and the one before if needed, see :mod:`._mcap.reopen`),
        keeps every intact record and continues after the last one; a torn tail is cut off
        (and saved beside the file as ``<name>.dropped-<offset>``), as is the summary of a
        closed file. A last file with damage is left untouched and the journal goes on in
        a new part file (:attr:`damaged`). What was recovered is in :attr:`recovered`;
        :attr:`needs_snapshot` says whether the file now written lacks a snapshot.

        Raises:
            JournalError: The file is missing, locked by another writer, or not a journal.
        """
        reopened = reopen(Path(path), options.chunked, options.fsync)
        writer = cls(
            reopened.base, reopened.part, options, reopened.recovered, reopened.damaged, library
        )
        for record in reopened.recovered.records:
            if record.topic == MISSION_TOPIC:
                writer._events_since_snapshot = 0
            elif record.topic == EVENTS_TOPIC:
                writer._events_since_snapshot += 1
                writer._newest_revision = max(writer._newest_revision, record.revision)
        _log.info(
            "resumed journal %s: %d records, continuing in %s at byte %d",
            reopened.base,
            len(reopened.recovered.records),
            reopened.part.path.name,
            writer.offset,
        )
        return writer

    @property
    def _part(self) -> PartFile:
        return self._files.part

    @property
    def path(self) -> Path:
        """The journal: its first file, which names every part for the readers."""
        return self._base

    @property
    def part_path(self) -> Path:
        """The file appends go to now."""
        return self._part.path

    @property
    def offset(self) -> int:
        """Bytes handed to the operating system so far in the current file (its size)."""
        return self._part.offset

    @property
    def chunked(self) -> bool:
        """Whether each append is written as its own chunk."""
        return self._part.chunked

    @property
    def closed(self) -> bool:
        """Whether close() has been called."""
        return self._part.fd is None

    @property
    def snapshot_due(self) -> bool:
        """Whether a snapshot should be appended: ``snapshot_every`` events since the last
        one, or the current file is full (the snapshot then starts the next part)."""
        return self._events_since_snapshot >= self._options.snapshot_every or self._files.full()

    @property
    def needs_snapshot(self) -> bool:
        """Whether the current file holds no snapshot yet (after a resume into a new part):
        append one before anything else so the file can start the mission on its own."""
        return self._part.snapshots == 0

    def require_space(self) -> None:
        """Raise StorageFull unless the journal's disk has room for a change: ask before
        applying one, since a change applied and then not journaled would be lost."""
        self.space.require()

    def append_event(self, event: RosMessage, log_time_ns: int) -> None:
        """Record one accepted change (``rosmc/MissionEvent``); durable when this returns."""
        self._append(EVENTS_TOPIC, event, log_time_ns, sync=True)

    def append_snapshot(self, mission: RosMessage, log_time_ns: int) -> None:
        """Record a full ``rosmc/Mission`` snapshot (and the library, once per part file);
        durable when this returns."""
        self._append(MISSION_TOPIC, mission, log_time_ns, sync=True)
        self._append_library(log_time_ns)

    def _append_library(self, log_time_ns: int) -> None:
        """Write the library after the first snapshot of a part file."""
        with self._lock:
            part = self._part.number
            due = self._library is not None and self._library_part != part
            self._library_part = part
        if due:
            self._append(LIBRARY_TOPIC, self._library, log_time_ns, sync=True)

    def append_replacement(self, event: RosMessage, mission: RosMessage, log_time_ns: int) -> None:
        """Record a change that replaces the mission (``rosmc/MissionEvent`` of kind
        MISSION_REPLACED) together with the new mission's snapshot, as one unit: one chunk
        written at once and synced, so that no crash leaves the event without the content
        it stands for (a chunk torn by a crash fails its CRC and is cut off whole). Durable
        when this returns."""
        self._append_unit([(EVENTS_TOPIC, event), (MISSION_TOPIC, mission)], log_time_ns, True)
        self._append_library(log_time_ns)

    def write_mark(self, fields: Mapping[str, str | int], sync: bool = False) -> None:
        """Keep the revision mark's fields in the head of the file being written and of the
        journal's first file (in place; see :mod:`._mcap.head_mark`), and in every part
        started after this. The part written is synced by its next record; the first file,
        once it is no longer written, when ``sync`` (a lease renewed).

        Raises:
            JournalError: A head cannot be written.
        """
        with self._lock:
            self._files.write_mark(fields, sync)

    def append_due_snapshot(self, mission: RosMessage, log_time_ns: int) -> bool:
        """Record ``mission`` if a snapshot is due, the journal open and room left for it
        (a periodic snapshot waits while the disk is nearly full); whether it did."""
        if not self.snapshot_due or self.closed or not self._room_for_telemetry(MISSION_TOPIC):
            return False
        self.append_snapshot(mission, log_time_ns)
        return True

    def append_report(self, report: RosMessage, log_time_ns: int) -> None:
        """Record a ``rosmc/RobotReport`` (written, never fsynced on its own).

        A report leads to a change, so it needs the room of one: StorageFull otherwise
        (the robot, unanswered, sends it again).
        """
        self.space.require()
        self._append(ROBOT_REPORTS_TOPIC, report, log_time_ns, sync=False)

    def append_command(self, record: RosMessage, log_time_ns: int) -> None:
        """Record a ``rosmc/CommandRecord`` (telemetry: written, never fsynced on its own)."""
        self._append(ROBOT_COMMANDS_TOPIC, record, log_time_ns, sync=False)

    def append_agent_states(self, states: RosMessage, log_time_ns: int) -> None:
        """Record a ``rosmc/AgentStates`` (telemetry: written, never fsynced on its own)."""
        self._append(AGENT_STATES_TOPIC, states, log_time_ns, sync=False)

    def append_telemetry(self, topic: str, msg: RosMessage, log_time_ns: int) -> None:
        """Record a message of one of :data:`TELEMETRY_TOPICS` (TF, science, world, ...).

        Written at once but never fsynced on its own: the next mission event's sync (or
        the close) makes it durable.
        """
        if topic not in TELEMETRY_TOPICS:
            raise JournalError(f"{topic} is not a telemetry channel of the journal")
        self._append(topic, msg, log_time_ns, sync=False)

    def start_next_part(self) -> None:
        """Go on in a new part file (after a resume that lost revisions, so that later
        resumes start from its snapshot and do not count the loss again); on failure keep
        writing this one."""
        with self._lock:
            self._part.open_fd()
            self._files.rotate()

    def sync(self) -> None:
        """Flush everything appended so far to the disk (fdatasync)."""
        with self._lock:
            self._part.sync()

    def close(self) -> None:
        """Write the summary and footer, sync and close; a closed journal is complete MCAP."""
        with self._lock:
            self._files.close_first_head()
            self._part.close()

    def abandon(self) -> None:
        """Close the file without a summary, as a crash leaves it; resume recovers it."""
        with self._lock:
            self._files.close_first_head()
            self._part.abandon()

    def __enter__(self) -> Self:
        return self

    def __exit__(
        self,
        exc_type: type[BaseException] | None,
        exc: BaseException | None,
        tb: TracebackType | None,
    ) -> None:
        self.close()

    def _append(self, topic: str, msg: RosMessage, log_time_ns: int, sync: bool) -> None:
        if not sync and not self._room_for_telemetry(topic):
            return
        self._append_unit([(topic, msg)], log_time_ns, sync)

    def _append_unit(
        self, messages: list[tuple[str, RosMessage]], log_time_ns: int, sync: bool
    ) -> None:
        """Write ``messages`` as one unit: one chunk (chunked layout) in one write."""
        for topic, msg in messages:
            expected = JOURNAL_TOPICS[topic]
            if getattr(msg, "_type", None) != expected:
                raise JournalError(f"{topic} records {expected}, not {type(msg).__name__}")
        data = [serialize(msg) for _, msg in messages]  # outside the lock: snapshots are big
        revision = -1  # of the snapshot or event written last: both start with a uint64 one
        if messages[-1][0] in (MISSION_TOPIC, EVENTS_TOPIC):
            revision = int.from_bytes(data[-1][:8], "little")
        with self._lock:
            self._part.open_fd()
            snapshot = messages[-1][0] == MISSION_TOPIC
            if self._files.rotation_due(snapshot, snapshot and revision < self._newest_revision):
                self._files.rotate()
            self._newest_revision = max(self._newest_revision, revision)
            part = self._part
            records: list[tuple[int, int, list[bytes]]] = []
            for (topic, _), body in zip(messages, data, strict=True):
                channel_id = self._files.channels[topic]
                earlier = sum(1 for r in records if r[0] == channel_id)
                sequence = (part.section.sequence(channel_id) + earlier) & 0xFFFFFFFF
                # The record is written in parts: a snapshot's megabytes are never copied.
                head = fmt.message_head(channel_id, sequence, log_time_ns, len(body))
                records.append((channel_id, log_time_ns, [head, body]))
            written: list[bytes] = [piece for _, _, parts in records for piece in parts]
            chunk_index = None
            if part.chunked:
                compress_from = self._options.compress_from
                written, chunk_index = part.section.chunk(part.offset, records, compress_from)
            part.write(written, sync, self._options.fsync)
            for channel_id, _, _ in records:
                part.section.count(channel_id, log_time_ns, chunk_index)
                chunk_index = None  # one index entry per chunk
            for topic, _ in messages:
                if topic == MISSION_TOPIC:
                    self._events_since_snapshot = 0
                    part.snapshots += 1
                elif topic == EVENTS_TOPIC:
                    self._events_since_snapshot += 1
                    self._files.events_in_part += 1

    def _room_for_telemetry(self, topic: str) -> bool:
        """Whether telemetry may still be written; skipped (said once) near a full disk."""
        try:
            self.space.require(telemetry=True)
        except StorageFull as full:
            if not self._telemetry_skipped:
                _log.warning(
                    "journal %s: %s; telemetry (%s, ...) is not journaled", self._base, full, topic
                )
            self._telemetry_skipped = True
            return False
        self._telemetry_skipped = False
        return True
