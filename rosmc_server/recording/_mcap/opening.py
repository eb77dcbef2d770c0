"""The snapshot a journal file opens with, read from its first bytes without a scan.

Every part file a :class:`~rosmc_server.recording.writer.JournalWriter` starts opens
with the same head (magic, header, the revision mark's Metadata record, the channel
declarations) followed by a snapshot: a chunk (or, in the bare layout, a message) whose
message starts with the snapshot's ``uint64 revision``. Reading that revision and the
chunk's start time tells a reviewer which file holds a revision or a moment, so it can
read that file alone instead of the whole journal.

Nothing here is checked against a CRC (only a prefix of the chunk is decompressed): a
caller must treat the answer as a hint and verify what it reads. Anything unexpected
(damage, an older journal's head, a file that opens with an event) gives None.
"""

from __future__ import annotations

import struct
from dataclasses import dataclass
from pathlib import Path

import zstandard
from mcap.opcode import Opcode

from rosmc_server.interface import MISSION_TOPIC
from rosmc_server.recording._mcap import records as fmt
from rosmc_server.recording.channels import JOURNAL_TOPICS, LIBRARY, PROFILE

_HEAD = fmt.RECORD_HEAD.size
_JOURNAL_HEAD = fmt.MAGIC + fmt.header(PROFILE, LIBRARY)
_MESSAGE = struct.Struct("<HIQQ")  # channel id, sequence, log time, publish time
_CHUNK_FIELDS = struct.Struct("<QQQI")  # start and end time, records' size, CRC
READ_BYTES = (65536, 1 << 20)
"""How much of a file is read for its opening snapshot: a little, then more if needed
(the declarations take about 30 kB, a zstd block of a snapshot's first 128 kB less)."""
_FIXED_MISSION_CHANNEL = list(JOURNAL_TOPICS).index(MISSION_TOPIC) + 1
"""The snapshot channel's id in a journal's fixed channel order (see :mod:`.layout`)."""
_SKIPPED = (Opcode.METADATA, Opcode.SCHEMA, Opcode.CHANNEL, Opcode.MESSAGE_INDEX)


@dataclass(frozen=True)
class Opening:
    """A file's opening snapshot: its revision and log time (ns)."""

    revision: int
    log_time: int


def opening_snapshot(path: Path) -> Opening | None:
    """The snapshot ``path`` opens with, or None if its first bytes do not show one."""
    for size in READ_BYTES:
        try:
            with path.open("rb") as file:
                data = file.read(size)
        except OSError:
            return None
        found = _opening(data)
        if found is not None or len(data) < size:
            return found
    return None


def _opening(data: bytes) -> Opening | None:
    if not data.startswith(_JOURNAL_HEAD):
        return None
    mission = _FIXED_MISSION_CHANNEL
    pos = len(_JOURNAL_HEAD)
    while True:
        head = fmt.record_head(data, pos)
        if head is None:
            return None
        opcode, length = head
        body = pos + _HEAD
        if opcode == Opcode.CHANNEL and body + length <= len(data):
            try:  # as declared, if its declaration is intact (an older journal's order)
                channel = fmt.parse_channel(data[body : body + length])
            except fmt.FormatError:
                channel = None
            if channel is not None and channel.topic == MISSION_TOPIC:
                mission = channel.id
        if opcode == Opcode.CHUNK:
            return _in_chunk(data[body : body + length], mission)
        if opcode == Opcode.MESSAGE:
            return _message(data[body : body + length], mission)
        if opcode not in _SKIPPED:
            return None
        pos = body + length


def _in_chunk(body: bytes, mission: int) -> Opening | None:
    """The first message of a chunk whose body starts ``body`` (perhaps cut short)."""
    if len(body) < _CHUNK_FIELDS.size + 4:
        return None
    pos = _CHUNK_FIELDS.size
    (name_length,) = struct.unpack_from("<I", body, pos)
    if name_length > 8:
        return None
    pos += 4
    compression = body[pos : pos + name_length]
    pos += name_length + 8  # the records' compressed size
    compressed = body[pos:]
    if compression == b"":
        records = compressed
    elif compression == b"zstd":
        try:  # a prefix of the frame gives a prefix of the records
            records = zstandard.ZstdDecompressor().decompressobj().decompress(compressed)
        except zstandard.ZstdError:
            return None
    else:
        return None
    head = fmt.record_head(records, 0)
    if head is None or head[0] != Opcode.MESSAGE:
        return None
    return _message(records[_HEAD:], mission)


def _message(body: bytes, mission: int) -> Opening | None:
    """A Message record's body (perhaps cut short) if it is a snapshot."""
    if len(body) < _MESSAGE.size + 8:
        return None
    channel, _, log_time, _ = _MESSAGE.unpack_from(body)
    if channel != mission:
        return None
    revision = int.from_bytes(body[_MESSAGE.size : _MESSAGE.size + 8], "little")
    return Opening(revision, log_time)
