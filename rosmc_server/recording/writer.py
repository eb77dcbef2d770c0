"""Appending accepted mission changes to an MCAP journal, durably, one write per change."""

import logging
import os
import threading
from dataclasses import dataclass
from pathlib import Path
from types import TracebackType
from typing import Self

from rosmc_server.interface import (
    AGENT_STATES_TOPIC,
    EVENTS_TOPIC,
    MISSION_TOPIC,
    ROBOT_REPORTS_TOPIC,
)
from rosmc_server.recording import _format as fmt
from rosmc_server.recording import _scan
from rosmc_server.recording._codec import RosMessage, serialize
from rosmc_server.recording._files import fsync_directory, open_locked, save_tail
from rosmc_server.recording._section import DataSection
from rosmc_server.recording.channels import JOURNAL_TOPICS, PROFILE, TELEMETRY_TOPICS
from rosmc_server.recording.errors import JournalError
from rosmc_server.recording.reader import JournalResult, decode_scan

_log = logging.getLogger(__name__)
LIBRARY = "rosmc-journal/1"


@dataclass(frozen=True)
class JournalOptions:
    """How a journal is written.

    Attributes:
        fsync: fdatasync after every event and snapshot, so an acknowledged change also
            survives a power loss (a process crash never loses one either way).
        chunked: One MCAP chunk (with its message index) per append, so the closed file is
            indexed and its snapshots compressed. False writes bare message records: 80 bytes
            less per event, but no compression, and indexed readers (Foxglove's among them)
            must fall back to reading the whole file. A resumed journal keeps its layout.
        snapshot_every: ``snapshot_due`` turns true after this many events.
        compress_from: zstd-compress a chunk whose records reach this many bytes (snapshots);
            0 never compresses.
    """

    fsync: bool = False
    chunked: bool = True
    snapshot_every: int = 500
    compress_from: int = 16384


class JournalWriter:
    """Appends mission events, snapshots and telemetry to one MCAP file.

    Every append reaches the operating system in a single ``write`` before it returns
    (and the disk, with ``fsync``), so a change acknowledged after ``append_event``
    survives a crash of the process. ``close`` adds the summary that makes the file a
    complete, indexed MCAP file. Open one with :meth:`create` or :meth:`resume`.
    Thread-safe: appends from several threads are written one after the other. An
    advisory file lock keeps a second writer (in any process) off the same file.
    """

    def __init__(
        self,
        path: Path,
        fd: int,
        section: DataSection,
        options: JournalOptions,
        chunked: bool,
        recovered: JournalResult | None = None,
    ) -> None:
        """Wrap an open, locked file positioned at its end; use create or resume instead."""
        self._path = path
        self._fd: int | None = fd
        self._section = section
        self._options = options
        self._chunked = chunked
        self._offset = os.lseek(fd, 0, os.SEEK_END)
        self._channels = section.channel_ids()
        self._events_since_snapshot = 0
        self._lock = threading.RLock()
        self.recovered = recovered
        """What resume recovered from the file (None for a new journal)."""

    @classmethod
    def create(
        cls,
        path: str | Path,
        snapshot: RosMessage,
        log_time_ns: int,
        options: JournalOptions = JournalOptions(),
    ) -> "JournalWriter":
        """Start a new journal that opens with ``snapshot``; never overwrites a file.

        Raises:
            JournalError: The file exists or cannot be written.
        """
        path = Path(path)
        writer = cls(
            path,
            open_locked(path, os.O_WRONLY | os.O_CREAT | os.O_EXCL),
            DataSection(),
            options,
            options.chunked,
        )
        try:
            preamble = fmt.MAGIC + fmt.header(PROFILE, LIBRARY) + writer._declare()
            writer._write(preamble, sync=False)
            writer.append_snapshot(snapshot, log_time_ns)
            if options.fsync:
                fsync_directory(path.parent)
        except (OSError, JournalError):
            writer.abandon()
            path.unlink()  # it holds nothing anybody was told about
            raise
        return writer

    @classmethod
    def resume(
        cls, path: str | Path, options: JournalOptions = JournalOptions()
    ) -> "JournalWriter":
        """Recover a journal and continue it in the same file.

        Keeps every intact record, cuts off a damaged tail (saving it beside the journal as
        ``<name>.dropped-<offset>``) or the summary of a closed file, and appends after the
        last intact record. What was recovered is in :attr:`recovered`.

        Raises:
            JournalError: The file is missing, locked by another writer, or not a journal.
        """
        path = Path(path)
        fd = open_locked(path, os.O_RDWR)
        try:
            scan = _scan.scan(path)
            if scan.profile != PROFILE:
                raise JournalError(
                    f"{path} is an MCAP file of profile {scan.profile!r}, not a journal"
                )
            if scan.top_level_messages and scan.chunk_indexes:
                raise JournalError(f"journal {path} mixes chunked and bare messages")
            chunked = bool(scan.chunk_indexes) if scan.messages else options.chunked
            recovered = decode_scan(scan)
            if not scan.complete and scan.dropped_bytes:
                save_tail(path, scan.data_end)
            os.ftruncate(fd, scan.data_end)
            writer = cls(path, fd, DataSection.from_scan(scan), options, chunked, recovered)
        except (OSError, JournalError) as err:
            os.close(fd)
            if isinstance(err, JournalError):
                raise
            raise JournalError(f"cannot resume journal {path}: {err.strerror}") from err
        try:
            writer._finish_resume(scan)
        except JournalError:
            writer.abandon()
            raise
        _log.info(
            "resumed journal %s: %d records, continuing at byte %d",
            path,
            len(recovered.records),
            writer.offset,
        )
        return writer

    @property
    def path(self) -> Path:
        """The journal file."""
        return self._path

    @property
    def offset(self) -> int:
        """Bytes handed to the operating system so far (the file size while open)."""
        return self._offset

    @property
    def chunked(self) -> bool:
        """Whether each append is written as its own chunk."""
        return self._chunked

    @property
    def closed(self) -> bool:
        """Whether close() has been called."""
        return self._fd is None

    @property
    def snapshot_due(self) -> bool:
        """Whether ``snapshot_every`` events were appended since the last snapshot."""
        return self._events_since_snapshot >= self._options.snapshot_every

    def append_event(self, event: RosMessage, log_time_ns: int) -> None:
        """Record one accepted change (``rosmc/MissionEvent``); durable when this returns."""
        self._append(EVENTS_TOPIC, event, log_time_ns, sync=True)

    def append_snapshot(self, mission: RosMessage, log_time_ns: int) -> None:
        """Record a full ``rosmc/Mission`` snapshot; durable when this returns."""
        self._append(MISSION_TOPIC, mission, log_time_ns, sync=True)

    def append_report(self, report: RosMessage, log_time_ns: int) -> None:
        """Record a ``rosmc/RobotReport`` (telemetry: written, never fsynced on its own)."""
        self._append(ROBOT_REPORTS_TOPIC, report, log_time_ns, sync=False)

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

    def sync(self) -> None:
        """Flush everything appended so far to the disk (fdatasync)."""
        with self._lock:
            try:
                os.fdatasync(self._open_fd())
            except OSError as err:
                raise JournalError(f"cannot sync journal {self._path}: {err.strerror}") from err

    def close(self) -> None:
        """Write the summary and footer, sync and close; a closed journal is complete MCAP."""
        with self._lock:
            if self._fd is None:
                return
            try:
                self._write(self._section.closing_bytes(self._offset), sync=False)
                os.fdatasync(self._open_fd())
            except OSError as err:
                raise JournalError(f"cannot close journal {self._path}: {err.strerror}") from err
            finally:
                self.abandon()

    def abandon(self) -> None:
        """Close the file without a summary, as a crash leaves it; resume recovers it."""
        with self._lock:
            if self._fd is not None:
                os.close(self._fd)
                self._fd = None

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
        expected = JOURNAL_TOPICS[topic]
        if getattr(msg, "_type", None) != expected:
            raise JournalError(f"{topic} records {expected}, not {type(msg).__name__}")
        channel_id = self._channels[topic]
        data = serialize(msg)  # outside the lock: a big snapshot takes a while
        with self._lock:
            record = fmt.message(channel_id, self._section.sequence(channel_id), log_time_ns, data)
            chunk_index = None
            if self._chunked:
                compress_from = self._options.compress_from
                record, chunk_index = self._section.chunk(
                    self._offset, channel_id, log_time_ns, record, compress_from
                )
            self._write(record, sync)
            self._section.count(channel_id, log_time_ns, chunk_index)
            if topic == MISSION_TOPIC:
                self._events_since_snapshot = 0
            elif topic == EVENTS_TOPIC:
                self._events_since_snapshot += 1

    def _write(self, data: bytes, sync: bool) -> None:
        """Write all of ``data`` at the end; on failure cut the file back and raise."""
        fd = self._open_fd()
        try:
            view = memoryview(data)
            while view:
                view = view[os.write(fd, view) :]
            if sync and self._options.fsync:
                os.fdatasync(fd)
        except OSError as err:
            try:  # a partial record must not stay in front of the next append
                os.ftruncate(fd, self._offset)
                os.lseek(fd, self._offset, os.SEEK_SET)
            except OSError:
                self.abandon()
            raise JournalError(f"cannot write journal {self._path}: {err.strerror}") from err
        self._offset += len(data)

    def _open_fd(self) -> int:
        if self._fd is None:
            raise JournalError(f"journal {self._path} is closed")
        return self._fd

    def _declare(self) -> bytes:
        """Declare the journal channels the file lacks; return their records."""
        records = self._section.declare(JOURNAL_TOPICS)
        self._channels = self._section.channel_ids()
        return records

    def _finish_resume(self, scan: _scan.ScanResult) -> None:
        """Restore the last chunk's cut-off message indexes and declare missing channels."""
        tail = self._section.restore_indexes(self._offset, scan.missing_indexes)
        tail += self._declare()
        if tail:
            self._write(tail, sync=True)
        for record in self.recovered.records if self.recovered else ():
            if record.topic == MISSION_TOPIC:
                self._events_since_snapshot = 0
            elif record.topic == EVENTS_TOPIC:
                self._events_since_snapshot += 1
