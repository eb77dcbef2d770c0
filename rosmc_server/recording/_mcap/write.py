"""Writing a journal file: its data section and the open, locked part file it goes to.

The writer hands every record to the file as soon as it exists; this class
encodes the records that need bookkeeping (schemas, channels, chunks) and
remembers what the summary written on close must list. The chunk indexes are
kept already encoded (about 90 bytes per chunk, not a Python object each): they
are the only thing that grows with every append.
"""

from __future__ import annotations

import os
import zlib
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path

from mcap.opcode import Opcode

from rosmc_server.core.documents.durable import fsync_directory
from rosmc_server.recording._mcap import head_mark, layout
from rosmc_server.recording._mcap import records as fmt
from rosmc_server.recording._mcap.files import open_locked
from rosmc_server.recording.channels import JOURNAL_TOPICS, LIBRARY, PROFILE
from rosmc_server.recording.errors import JournalError


@dataclass
class DataSection:
    """Schemas, channels, chunk indexes and message statistics of the records written."""

    schemas: dict[int, fmt.SchemaRecord] = field(default_factory=dict)
    channels: dict[int, fmt.ChannelRecord] = field(default_factory=dict)
    counts: dict[int, int] = field(default_factory=dict)
    start_time: int = 0
    end_time: int = 0
    chunks: int = 0
    _indexes: bytearray = field(default_factory=bytearray)  # encoded, all but the last
    _last_index: fmt.ChunkIndexRecord | None = None  # kept whole: resume may extend it

    @classmethod
    def journal(cls) -> DataSection:
        """The section of a new journal: every journal channel declared, in the fixed order.

        A journal's channel and schema ids follow from :data:`JOURNAL_TOPICS` alone, so
        a reader can still tell a channel whose declaration was damaged.
        """
        schemas, channels = layout.journal_declarations()
        return cls(schemas, channels)

    def add_index(self, index: fmt.ChunkIndexRecord) -> None:
        """Remember a written chunk for the summary."""
        if self._last_index is not None:
            self._indexes += fmt.chunk_index(self._last_index)
        self._last_index = index
        self.chunks += 1

    def channel_ids(self) -> dict[str, int]:
        """Channel id of each topic."""
        return {c.topic: c.id for c in self.channels.values()}

    def declare(self, topics: Mapping[str, str]) -> bytes:
        """Register each topic (name -> message type) not declared yet; return its records."""
        return layout.declare(self.schemas, self.channels, topics)

    def count(
        self, channel_id: int, log_time: int, chunk_index: fmt.ChunkIndexRecord | None = None
    ) -> None:
        """Count one more message written on a channel (in the chunk ``chunk_index`` lists)."""
        if chunk_index is not None:
            self.add_index(chunk_index)
        if not self.counts:
            self.start_time = self.end_time = log_time
        self.start_time = min(self.start_time, log_time)
        self.end_time = max(self.end_time, log_time)
        self.counts[channel_id] = self.counts.get(channel_id, 0) + 1

    def sequence(self, channel_id: int) -> int:
        """Sequence number of the next message on a channel."""
        return self.counts.get(channel_id, 0) & 0xFFFFFFFF

    def chunk(
        self,
        offset: int,
        messages: Sequence[tuple[int, int, Sequence[bytes]]],
        compress_from: int,
    ) -> tuple[list[bytes], fmt.ChunkIndexRecord]:
        """Wrap message records (each ``(channel id, log time, record in parts)``) in one
        chunk with its message indexes.

        The chunk goes at ``offset``; it is zstd-compressed when its records reach
        ``compress_from`` bytes (> 0). Returns the chunk's bytes in parts (the records'
        parts are not joined: a snapshot's megabytes are not copied on their way to the
        file) and its index entry, for :meth:`count` once written. A chunk is one unit
        for every reader: its CRC covers all its records, so a crash that tears it loses
        all of them, never some.
        """
        size = crc = 0
        entries: dict[int, list[tuple[int, int]]] = {}
        parts: list[bytes] = []
        for channel_id, log_time, record in messages:
            entries.setdefault(channel_id, []).append((log_time, size))
            for part in record:
                size += len(part)
                crc = zlib.crc32(part, crc)
            parts += record
        start = min(log_time for _, log_time, _ in messages)
        end = max(log_time for _, log_time, _ in messages)
        compression, payload = "", parts
        if 0 < compress_from <= size:
            compression, payload = fmt.compress_parts(parts)
        payload_size = sum(map(len, payload))
        chunk_record = fmt.ChunkRecord(start, end, size, crc, compression, b"")
        head = fmt.chunk_head(chunk_record, payload_size)
        chunk_length = len(head) + payload_size
        indexes: list[bytes] = []
        index_offsets: list[tuple[int, int]] = []
        for channel_id, channel_entries in entries.items():
            index_offsets.append((channel_id, offset + chunk_length + sum(map(len, indexes))))
            indexes.append(fmt.message_index(channel_id, channel_entries))
        return [head, *payload, *indexes], fmt.ChunkIndexRecord(
            message_start_time=start,
            message_end_time=end,
            chunk_start_offset=offset,
            chunk_length=chunk_length,
            message_index_offsets=tuple(index_offsets),
            message_index_length=sum(map(len, indexes)),
            compression=compression,
            compressed_size=payload_size,
            uncompressed_size=size,
        )

    def restore_indexes(self, offset: int, missing: Mapping[int, list[tuple[int, int]]]) -> bytes:
        """Return the message indexes the last chunk lost, to go at ``offset`` right after it."""
        last = self._last_index
        if last is None or not missing:
            return b""
        offsets = list(last.message_index_offsets)
        records = b""
        for channel_id, entries in missing.items():
            offsets.append((channel_id, offset + len(records)))
            records += fmt.message_index(channel_id, entries)
        self._last_index = replace(
            last,
            message_index_offsets=tuple(offsets),
            message_index_length=last.message_index_length + len(records),
        )
        return records

    def closing_bytes(self, data_end: int) -> bytes:
        """Return Data End, the summary, the footer and the closing magic.

        Args:
            data_end: File offset at which the Data End record will be written.
        """
        closing = fmt.data_end()
        summary_start = data_end + len(closing)
        groups = [
            (Opcode.SCHEMA, b"".join(fmt.schema(s) for s in self.schemas.values())),
            (Opcode.CHANNEL, b"".join(fmt.channel(c) for c in self.channels.values())),
            (Opcode.STATISTICS, self._statistics()),
            (Opcode.CHUNK_INDEX, self._chunk_indexes()),
        ]
        summary = b""
        offsets = b""
        for opcode, group in groups:
            if group:
                offsets += fmt.summary_offset(opcode, summary_start + len(summary), len(group))
                summary += group
        summary_offset_start = summary_start + len(summary)
        summary += offsets
        footer = fmt.footer(summary_start, summary_offset_start, summary)
        return closing + summary + footer + fmt.MAGIC

    def _statistics(self) -> bytes:
        return fmt.statistics(
            schemas=len(self.schemas),
            channels=len(self.channels),
            chunks=self.chunks,
            counts=self.counts,
            start=self.start_time,
            end=self.end_time,
        )

    def _chunk_indexes(self) -> bytes:
        last = b"" if self._last_index is None else fmt.chunk_index(self._last_index)
        return bytes(self._indexes) + last


@dataclass
class PartFile:
    """A locked journal file being appended to, positioned at its end.

    Attributes:
        path: The file.
        number: Its place in the journal's chain (1 for the first file).
        fd: The open descriptor (None once closed).
        section: What its data section holds (for the summary written on close).
        offset: Bytes handed to the operating system so far (the file size while open).
        chunked: Whether each append is written as its own chunk.
        snapshots: Snapshots in it (a part without one cannot start a mission).
        slots: File offsets of the two revision-mark slots at its head (None: a file of
            an older journal, written before the head held a mark; see :mod:`.head_mark`).
    """

    path: Path
    number: int
    fd: int | None
    section: DataSection
    offset: int
    chunked: bool
    snapshots: int = 0
    slots: tuple[int, int] | None = None

    @classmethod
    def create(cls, path: Path, number: int, chunked: bool, durable: bool) -> PartFile:
        """Create a new file with the MCAP header and every journal channel declared.

        Raises:
            JournalError: The file exists or cannot be written.
        """
        fd = open_locked(path, os.O_WRONLY | os.O_CREAT | os.O_EXCL)
        head = fmt.MAGIC + fmt.header(PROFILE, LIBRARY)
        mark = head_mark.mark_record(len(head))
        part = cls(path, number, fd, DataSection(), 0, chunked, slots=mark.slots)
        preamble = head + mark.data + part.section.declare(JOURNAL_TOPICS)
        try:
            part.write(preamble, sync=False, durable=False)
            if durable:
                fsync_directory(path.parent)
        except (OSError, JournalError) as err:
            part.abandon()
            path.unlink()  # it holds nothing anybody was told about
            if isinstance(err, JournalError):
                raise
            raise JournalError(f"cannot create journal {path}: {err.strerror}") from err
        return part

    def write(self, data: bytes | Sequence[bytes], sync: bool, durable: bool) -> None:
        """Write all of ``data`` (bytes, or parts written in order) at the end.

        fdatasync if ``sync and durable``. On failure the file is cut back to where it
        was and JournalError raised.
        """
        fd = self.open_fd()
        parts = [data] if isinstance(data, bytes) else data
        try:
            size = _write_all(fd, parts)
            if sync and durable:
                os.fdatasync(fd)
        except OSError as err:
            try:  # a partial record must not stay in front of the next append
                os.ftruncate(fd, self.offset)
                os.lseek(fd, self.offset, os.SEEK_SET)
            except OSError:
                self.abandon()
            raise JournalError(f"cannot write journal {self.path}: {err.strerror}") from err
        self.offset += size

    def write_mark(self, fields: Mapping[str, str | int], seq: int) -> None:
        """Rewrite the older of the head's two mark slots in place (never synced on its own:
        the next record's fdatasync carries it). Nothing for a file without slots.

        Raises:
            JournalError: The slot cannot be written.
        """
        if self.slots is None:
            return
        slot = head_mark.encode_slot(seq, fields)
        try:
            os.pwrite(self.open_fd(), slot, self.slots[seq % 2])
        except OSError as err:
            raise JournalError(f"cannot write journal {self.path}: {err.strerror}") from err

    def sync(self) -> None:
        """fdatasync the file."""
        try:
            os.fdatasync(self.open_fd())
        except OSError as err:
            raise JournalError(f"cannot sync journal {self.path}: {err.strerror}") from err

    def close(self) -> None:
        """Write the summary and footer, sync and close: the file is complete MCAP."""
        if self.fd is None:
            return
        try:
            self.write(self.section.closing_bytes(self.offset), sync=False, durable=False)
            os.fdatasync(self.open_fd())
        except OSError as err:
            raise JournalError(f"cannot close journal {self.path}: {err.strerror}") from err
        finally:
            self.abandon()

    def abandon(self) -> None:
        """Close the file without a summary, as a crash leaves it."""
        if self.fd is not None:
            os.close(self.fd)
            self.fd = None

    def open_fd(self) -> int:
        """The descriptor; JournalError if the file is closed."""
        if self.fd is None:
            raise JournalError(f"journal {self.path} is closed")
        return self.fd


def _write_all(fd: int, parts: Sequence[bytes]) -> int:
    """Write every part in order with as few system calls as the kernel allows; the size."""
    views = [memoryview(part) for part in parts if part]
    size = sum(len(view) for view in views)
    while views:
        written = os.writev(fd, views)
        while views and written >= len(views[0]):
            written -= len(views.pop(0))
        if written:
            views[0] = views[0][written:]
    return size
