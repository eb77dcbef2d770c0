"""Byte layout of the MCAP records the journal writes and reads (MCAP format, version 0).

The journal encodes and parses records itself instead of going through
``mcap.writer.Writer``: it must know the file offset of every record to resume
a damaged file, and it must put each append on disk as a whole without
buffering. The layout follows https://mcap.dev/spec; the tests check every file
against the ``mcap`` package's own readers.
"""

import importlib
import struct
import zlib
from collections.abc import Iterator, Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import zstandard
from mcap.opcode import Opcode

MAGIC = b"\x89MCAP0\r\n"
RECORD_HEAD = struct.Struct("<BQ")  # opcode, body length
_MESSAGE_HEAD = struct.Struct("<BQHIQQ")  # record head + channel, sequence, log/publish time
_U16 = struct.Struct("<H")
_U32 = struct.Struct("<I")
_U64 = struct.Struct("<Q")


class FormatError(ValueError):
    """A record body is shorter than its fields or holds an impossible value."""


@dataclass(frozen=True)
class SchemaRecord:
    """A Schema record: a message definition, referenced by channels."""

    id: int
    name: str
    encoding: str
    data: bytes


@dataclass(frozen=True)
class ChannelRecord:
    """A Channel record: a topic with its message encoding and schema."""

    id: int
    schema_id: int
    topic: str
    message_encoding: str


@dataclass(frozen=True)
class MessageRecord:
    """A Message record: one serialised message on a channel."""

    channel_id: int
    sequence: int
    log_time: int
    publish_time: int
    data: bytes


@dataclass(frozen=True)
class ChunkRecord:
    """A Chunk record: a (possibly compressed) run of schema, channel and message records."""

    message_start_time: int
    message_end_time: int
    uncompressed_size: int
    uncompressed_crc: int
    compression: str
    data: bytes


@dataclass(frozen=True)
class ChunkIndexRecord:
    """A Chunk Index record of the summary: where a chunk and its message indexes are."""

    message_start_time: int
    message_end_time: int
    chunk_start_offset: int
    chunk_length: int
    message_index_offsets: tuple[tuple[int, int], ...]  # (channel id, file offset)
    message_index_length: int
    compression: str
    compressed_size: int
    uncompressed_size: int


def _str(value: str) -> bytes:
    encoded = value.encode()
    return _U32.pack(len(encoded)) + encoded


def record(opcode: Opcode, body: bytes) -> bytes:
    """Frame ``body`` as one record: opcode, length, body."""
    return RECORD_HEAD.pack(opcode, len(body)) + body


def header(profile: str, library: str) -> bytes:
    """Encode a Header record."""
    return record(Opcode.HEADER, _str(profile) + _str(library))


def schema(rec: SchemaRecord) -> bytes:
    """Encode a Schema record."""
    body = _U16.pack(rec.id) + _str(rec.name) + _str(rec.encoding)
    return record(Opcode.SCHEMA, body + _U32.pack(len(rec.data)) + rec.data)


def channel(rec: ChannelRecord) -> bytes:
    """Encode a Channel record (without channel metadata)."""
    body = struct.pack("<HH", rec.id, rec.schema_id) + _str(rec.topic)
    return record(Opcode.CHANNEL, body + _str(rec.message_encoding) + _U32.pack(0))


def message(channel_id: int, sequence: int, log_time: int, data: bytes) -> bytes:
    """Encode a Message record; the publish time is the log time."""
    return message_head(channel_id, sequence, log_time, len(data)) + data


def message_head(channel_id: int, sequence: int, log_time: int, size: int) -> bytes:
    """The head of a Message record whose ``size`` bytes of data follow it."""
    return _MESSAGE_HEAD.pack(Opcode.MESSAGE, 22 + size, channel_id, sequence, log_time, log_time)


def chunk(rec: ChunkRecord) -> bytes:
    """Encode a Chunk record."""
    return chunk_head(rec, len(rec.data)) + rec.data


def chunk_head(rec: ChunkRecord, size: int) -> bytes:
    """The head of a Chunk record whose ``size`` bytes of records follow it (``rec.data``
    is not read: a writer may hold the records in parts)."""
    times = struct.pack(
        "<QQQI",
        rec.message_start_time,
        rec.message_end_time,
        rec.uncompressed_size,
        rec.uncompressed_crc,
    )
    fields = times + _str(rec.compression) + _U64.pack(size)
    return RECORD_HEAD.pack(Opcode.CHUNK, len(fields) + size) + fields


def message_index(channel_id: int, entries: list[tuple[int, int]]) -> bytes:
    """Encode a Message Index record: (log time, offset in the chunk's records) pairs."""
    packed = b"".join(struct.pack("<QQ", t, o) for t, o in entries)
    return record(Opcode.MESSAGE_INDEX, _U16.pack(channel_id) + _U32.pack(len(packed)) + packed)


def chunk_index(rec: ChunkIndexRecord) -> bytes:
    """Encode a Chunk Index record."""
    offsets = b"".join(struct.pack("<HQ", c, o) for c, o in rec.message_index_offsets)
    body = struct.pack(
        "<QQQQ",
        rec.message_start_time,
        rec.message_end_time,
        rec.chunk_start_offset,
        rec.chunk_length,
    )
    body += _U32.pack(len(offsets)) + offsets + _U64.pack(rec.message_index_length)
    body += _str(rec.compression) + struct.pack("<QQ", rec.compressed_size, rec.uncompressed_size)
    return record(Opcode.CHUNK_INDEX, body)


def statistics(
    schemas: int, channels: int, chunks: int, counts: Mapping[int, int], start: int, end: int
) -> bytes:
    """Encode a Statistics record (the journal writes no attachments or metadata)."""
    per_channel = b"".join(struct.pack("<HQ", c, n) for c, n in sorted(counts.items()))
    body = struct.pack(
        "<QHIIIIQQ", sum(counts.values()), schemas, channels, 0, 0, chunks, start, end
    )
    return record(Opcode.STATISTICS, body + _U32.pack(len(per_channel)) + per_channel)


def summary_offset(group_opcode: Opcode, start: int, length: int) -> bytes:
    """Encode a Summary Offset record pointing at one group of summary records."""
    return record(Opcode.SUMMARY_OFFSET, struct.pack("<BQQ", group_opcode, start, length))


def data_end() -> bytes:
    """Encode the Data End record (no data section CRC: the file is written piecewise)."""
    return record(Opcode.DATA_END, _U32.pack(0))


def footer(summary_start: int, summary_offset_start: int, summary: bytes) -> bytes:
    """Encode the Footer; its CRC covers the summary and the footer's own leading fields."""
    prefix = struct.pack("<BQQQ", Opcode.FOOTER, 20, summary_start, summary_offset_start)
    return prefix + _U32.pack(zlib.crc32(prefix, zlib.crc32(summary)))


def compress(data: bytes) -> tuple[str, bytes]:
    """Compress a chunk's records with zstd."""
    return "zstd", zstandard.ZstdCompressor(level=3).compress(data)


def compress_parts(parts: Sequence[bytes]) -> tuple[str, list[bytes]]:
    """Compress a chunk's records, held in parts, into one zstd frame held in parts.

    The frame declares its content size, as :func:`compress`'s does; no part is joined
    (a snapshot's megabytes are not copied to be compressed).
    """
    stream = zstandard.ZstdCompressor(level=3).compressobj(size=sum(map(len, parts)))
    out = [stream.compress(part) for part in parts]
    out.append(stream.flush())
    return "zstd", [piece for piece in out if piece]


def decompress(compression: str, data: bytes, size: int) -> bytes:
    """Return a chunk's records; raise FormatError for an unknown or corrupt compression."""
    if compression == "":
        return data
    if compression == "lz4":  # not written by the journal; other MCAP writers use it
        try:
            lz4: Any = importlib.import_module("lz4.frame")
            return bytes(lz4.decompress(data))
        except ImportError as err:
            raise FormatError("an lz4-compressed chunk needs the lz4 package") from err
        except RuntimeError as err:
            raise FormatError(f"lz4: {err}") from err
    if compression != "zstd":
        raise FormatError(f"unsupported chunk compression {compression!r}")
    try:
        return zstandard.ZstdDecompressor().decompress(data, max_output_size=size)
    except zstandard.ZstdError as err:
        raise FormatError(f"zstd: {err}") from err


class Cursor:
    """Reads little-endian fields from ``data[start:end]``; raises FormatError past its end."""

    def __init__(self, data: bytes, start: int = 0, end: int | None = None) -> None:
        self._data = data
        self._start = self._pos = start
        self._end = len(data) if end is None else end

    @property
    def pos(self) -> int:
        """Offset in ``data`` of the next field."""
        return self._pos

    def take(self, size: int) -> bytes:
        """Return the next ``size`` bytes."""
        end = self._pos + size
        if end > self._end:
            raise FormatError(
                f"a field needs {end - self._start} bytes, the record has {self._end - self._start}"
            )
        chunk_ = self._data[self._pos : end]
        self._pos = end
        return chunk_

    def u16(self) -> int:
        """Read an unsigned 16-bit integer."""
        return int(_U16.unpack(self.take(2))[0])

    def u32(self) -> int:
        """Read an unsigned 32-bit integer."""
        return int(_U32.unpack(self.take(4))[0])

    def u64(self) -> int:
        """Read an unsigned 64-bit integer."""
        return int(_U64.unpack(self.take(8))[0])

    def string(self) -> str:
        """Read a length-prefixed UTF-8 string."""
        try:
            return self.take(self.u32()).decode()
        except UnicodeDecodeError as err:
            raise FormatError(f"a string is not UTF-8: {err}") from err


def parse_header(body: bytes) -> str:
    """Return the profile of a Header record."""
    return Cursor(body).string()


def read_header(data: bytes, start: int) -> tuple[str, str, int]:
    """Decode a Header body at ``start`` by its own fields: (profile, library, where it ends).

    Does not trust the record's length field, so a damaged one can be told apart.
    """
    cur = Cursor(data, start)
    return cur.string(), cur.string(), cur.pos


def parse_schema(body: bytes) -> SchemaRecord:
    """Decode a Schema record (FormatError unless its fields fill it exactly)."""
    cur = Cursor(body)
    rec = SchemaRecord(cur.u16(), cur.string(), cur.string(), cur.take(cur.u32()))
    _filled(cur, body, "schema")
    return rec


def parse_channel(body: bytes) -> ChannelRecord:
    """Decode a Channel record (its metadata is skipped; FormatError unless filled exactly)."""
    cur = Cursor(body)
    id_, schema_id = cur.u16(), cur.u16()
    rec = ChannelRecord(id_, schema_id, cur.string(), cur.string())
    cur.take(cur.u32())  # the metadata map, by its byte length
    _filled(cur, body, "channel")
    return rec


def _filled(cur: Cursor, body: bytes, what: str) -> None:
    """A declaration has no checksum: a record length that disagrees with its own fields
    (a damaged length) would otherwise swallow the records after it."""
    if cur.pos != len(body):
        raise FormatError(
            f"the {what} record's length says {len(body)} bytes, its fields {cur.pos}"
        )


def parse_message(body: bytes) -> MessageRecord:
    """Decode a Message record."""
    if len(body) < 22:
        raise FormatError(f"a message record needs at least 22 bytes, it has {len(body)}")
    channel_id, sequence, log_time, publish_time = struct.unpack_from("<HIQQ", body)
    return MessageRecord(channel_id, sequence, log_time, publish_time, body[22:])


def parse_chunk(body: bytes) -> ChunkRecord:
    """Decode a Chunk record and check its size and CRC; return it with its records."""
    rec, end = read_chunk(body, 0)
    if end != len(body):
        raise FormatError(f"its length field says {len(body)} bytes, its content takes {end}")
    return rec


def read_chunk(data: bytes, start: int) -> tuple[ChunkRecord, int]:
    """Decode a Chunk body at ``start`` by its own fields; return it and where it ends.

    Does not trust the record's length field: a chunk whose content passes its CRC is
    intact even when the length (or opcode) in front of it is damaged.
    """
    cur = Cursor(data, start)
    begin, end, size, crc = cur.u64(), cur.u64(), cur.u64(), cur.u32()
    name_length = cur.u32()
    if name_length > 8:  # no compression has a longer name: refuse before reading garbage
        raise FormatError("a chunk names an impossible compression")
    compression = cur.take(name_length).decode(errors="replace")
    records = decompress(compression, cur.take(cur.u64()), size)
    if len(records) != size:
        raise FormatError(f"a chunk holds {len(records)} bytes, its header says {size}")
    if crc and zlib.crc32(records) != crc:
        raise FormatError("its CRC does not match its content")
    return ChunkRecord(begin, end, size, crc, compression, records), cur.pos


def read_message_index(data: bytes, start: int) -> tuple[int, list[tuple[int, int]], int]:
    """Decode a Message Index body at ``start``: (channel id, entries, where it ends)."""
    cur = Cursor(data, start)
    channel_id, length = cur.u16(), cur.u32()
    if length % 16:
        raise FormatError(f"a message index of {length} bytes is not a list of entries")
    entries = [struct.unpack_from("<QQ", cur.take(16)) for _ in range(length // 16)]
    return channel_id, [(int(t), int(o)) for t, o in entries], cur.pos


def record_head(data: bytes, pos: int) -> tuple[int, int] | None:
    """(opcode, body length) of the record at ``pos``, or None if its head is cut off."""
    if pos + RECORD_HEAD.size > len(data):
        return None
    opcode, length = RECORD_HEAD.unpack_from(data, pos)
    return int(opcode), int(length)


def iter_records(data: bytes, start: int = 0) -> Iterator[tuple[int, int, bytes]]:
    """Yield (offset, opcode, body) of the complete records in ``data`` from ``start``.

    Stops at the first record that does not fit; the caller compares the last end
    offset with ``len(data)`` to learn whether something was cut short.
    """
    pos, size = start, len(data)
    while pos + RECORD_HEAD.size <= size:
        opcode, length = RECORD_HEAD.unpack_from(data, pos)
        end = pos + RECORD_HEAD.size + length
        if end > size:
            return
        yield pos, opcode, data[pos + RECORD_HEAD.size : end]
        pos = end
