"""The data section of a journal being written: what it holds and how its records look.

The writer hands every record to the file as soon as it exists; this class
encodes the records that need bookkeeping (schemas, channels, chunks) and
remembers what the summary written on close must list. The chunk indexes are
kept already encoded (about 90 bytes per chunk, not a Python object each): they
are the only thing that grows with every append.
"""

from __future__ import annotations

import zlib
from collections.abc import Mapping
from dataclasses import dataclass, field, replace
from typing import TYPE_CHECKING

from mcap.opcode import Opcode

from rosmc_server.recording import _format as fmt
from rosmc_server.recording._codec import schema_of
from rosmc_server.recording.channels import JOURNAL_TOPICS, MESSAGE_ENCODING, SCHEMA_ENCODING

if TYPE_CHECKING:
    from rosmc_server.recording._scan import ScanResult


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
    def from_scan(cls, scan: ScanResult) -> DataSection:
        """Rebuild the state of the data section a scan found."""
        section = cls(dict(scan.schemas), dict(scan.channels))
        for index in scan.chunk_indexes:
            section.add_index(index)
        for msg in scan.messages:
            section.count(msg.channel_id, msg.log_time)
        return section

    @classmethod
    def journal(cls) -> DataSection:
        """The section of a new journal: every journal channel declared, in the fixed order.

        A journal's channel and schema ids follow from :data:`JOURNAL_TOPICS` alone, so
        a reader can still tell a channel whose declaration was damaged.
        """
        section = cls()
        section.declare(JOURNAL_TOPICS)
        return section

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
        records = b""
        declared = self.channel_ids()
        schema_ids = {s.name: s.id for s in self.schemas.values()}
        for topic, type_name in topics.items():
            if topic in declared:
                continue
            if type_name not in schema_ids:
                schema_id = schema_ids[type_name] = max(self.schemas, default=0) + 1
                schema = fmt.SchemaRecord(
                    schema_id, type_name, SCHEMA_ENCODING, schema_of(type_name)
                )
                self.schemas[schema_id] = schema
                records += fmt.schema(schema)
            channel_id = max(self.channels, default=0) + 1
            channel = fmt.ChannelRecord(channel_id, schema_ids[type_name], topic, MESSAGE_ENCODING)
            self.channels[channel_id] = channel
            records += fmt.channel(channel)
        return records

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
        self, offset: int, channel_id: int, log_time: int, message: bytes, compress_from: int
    ) -> tuple[bytes, fmt.ChunkIndexRecord]:
        """Wrap one message record in a chunk with its message index, to go at ``offset``.

        The chunk is zstd-compressed when the record reaches ``compress_from`` bytes (> 0).
        Returns the bytes and the chunk's index entry, for :meth:`count` once written.
        """
        compression, payload = "", message
        if 0 < compress_from <= len(message):
            compression, payload = fmt.compress(message)
        chunk = fmt.chunk(
            fmt.ChunkRecord(
                log_time, log_time, len(message), zlib.crc32(message), compression, payload
            )
        )
        index = fmt.message_index(channel_id, [(log_time, 0)])
        return chunk + index, fmt.ChunkIndexRecord(
            message_start_time=log_time,
            message_end_time=log_time,
            chunk_start_offset=offset,
            chunk_length=len(chunk),
            message_index_offsets=((channel_id, offset + len(chunk)),),
            message_index_length=len(index),
            compression=compression,
            compressed_size=len(payload),
            uncompressed_size=len(message),
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
