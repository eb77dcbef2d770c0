"""Sequential, damage-tolerant scan of an MCAP file.

A journal whose writer was killed has no summary and may end inside a record.
The scan therefore never trusts the summary: it walks the records from the
header on, keeps every complete one, and stops at the first record that is cut
short or damaged. What it found is everything the writer needs to continue the
file (schemas, channels, chunk indexes, statistics and the offset to continue
at) and everything the reader needs to decode the messages.
"""

from dataclasses import dataclass, field, replace
from pathlib import Path

from mcap.opcode import Opcode

from rosmc_server.recording import _format as fmt
from rosmc_server.recording.errors import JournalError


@dataclass
class ScanResult:
    """What a sequential scan found in an MCAP file (see module docstring)."""

    path: Path
    size: int
    profile: str
    schemas: dict[int, fmt.SchemaRecord] = field(default_factory=dict)
    channels: dict[int, fmt.ChannelRecord] = field(default_factory=dict)
    messages: list[fmt.MessageRecord] = field(default_factory=list)
    chunk_indexes: list[fmt.ChunkIndexRecord] = field(default_factory=list)
    missing_indexes: dict[int, list[tuple[int, int]]] = field(default_factory=dict)
    """Message indexes the last chunk should have but lacks (cut off after the chunk)."""
    top_level_messages: int = 0
    data_end: int = 0
    """Offset just after the last intact record of the data section: where to continue."""
    complete: bool = False
    dropped_bytes: int = 0
    warnings: list[str] = field(default_factory=list)


class _Damage(Exception):
    """A record that is complete by its length but cannot be what it claims to be."""


def scan(path: Path) -> ScanResult:
    """Scan ``path`` from the start; raise JournalError if it is not a journal at all."""
    try:
        # Read, not mapped: a writer truncating the file meanwhile must not kill us (SIGBUS).
        data = path.read_bytes()
    except OSError as err:
        raise JournalError(f"cannot read journal {path}: {err.strerror or err}") from err
    size = len(data)
    if size == 0:
        raise JournalError(f"journal {path} is empty (0 bytes)")
    if data[: len(fmt.MAGIC)] != fmt.MAGIC[:size]:
        raise JournalError(f"{path} is not an MCAP file (it does not start with the MCAP magic)")
    head = _first_record(data)
    if head is None:
        raise JournalError(
            f"journal {path} holds only {size} bytes: it was cut short before its MCAP header "
            "was complete, so it holds no records"
        )
    if head[0] != Opcode.HEADER:
        raise JournalError(f"{path} is not a valid MCAP file (its first record is not a header)")
    try:
        fmt.parse_header(head[1])
    except fmt.FormatError as err:
        raise JournalError(
            f"{path} is not a valid MCAP file (its header is damaged: {err})"
        ) from err
    result = ScanResult(path=path, size=size, profile=fmt.parse_header(head[1]))
    _Walker(result, data).walk()
    return result


def _first_record(data: bytes) -> tuple[int, bytes] | None:
    for _offset, opcode, body in fmt.iter_records(data, len(fmt.MAGIC)):
        return opcode, body
    return None


class _Walker:
    """Walks the records once, filling a ScanResult."""

    def __init__(self, result: ScanResult, data: bytes) -> None:
        self._r = result
        self._data = data
        self._in_summary = False
        self._after_chunk = False  # message index records may follow a chunk

    def walk(self) -> None:
        """Read every record; then set the data end, dropped bytes and warnings."""
        r = self._r
        r.data_end = len(fmt.MAGIC)
        damage = ""
        for offset, opcode, body in fmt.iter_records(self._data, r.data_end):
            end = offset + fmt.RECORD_HEAD.size + len(body)
            if self._in_summary:
                if opcode == Opcode.FOOTER:
                    self._closing(end)
                    break
                continue
            try:
                self._record(offset, opcode, body)
            except (_Damage, fmt.FormatError) as err:
                damage = f"a damaged {_name(opcode)} record at offset {offset}: {err}"
                break
            if opcode == Opcode.DATA_END:
                self._in_summary = True
            elif opcode == Opcode.FOOTER:  # a summary-less file may omit Data End
                self._closing(end)
                break
            else:
                r.data_end = end
        if r.complete:
            return
        r.dropped_bytes = r.size - r.data_end
        if damage:
            self._warn(f"dropped the last {r.dropped_bytes} bytes ({damage})")
        elif self._in_summary:
            self._warn(
                f"dropped the last {r.dropped_bytes} bytes (an unfinished summary written while "
                "closing; every data record is intact)"
            )
        elif r.dropped_bytes:
            self._warn(f"dropped the last {r.dropped_bytes} bytes (a record cut short)")
        self._warn(f"was not closed cleanly (no footer); recovered {len(r.messages)} messages")

    def _warn(self, text: str) -> None:
        self._r.warnings.append(f"journal {self._r.path}: {text}")

    def _closing(self, footer_end: int) -> None:
        r = self._r
        magic = self._data[footer_end : footer_end + len(fmt.MAGIC)]
        if magic != fmt.MAGIC:
            self._in_summary = True  # counts as an unfinished summary
            return
        r.complete = True
        trailing = r.size - footer_end - len(fmt.MAGIC)
        if trailing:
            self._warn(f"ignored {trailing} bytes after the end of the MCAP file")

    def _record(self, offset: int, opcode: int, body: bytes) -> None:
        after_chunk, self._after_chunk = self._after_chunk, False
        r = self._r
        if not (after_chunk and opcode == Opcode.MESSAGE_INDEX):
            r.missing_indexes = {}  # message indexes belong right after their chunk
        if opcode == 0:
            raise _Damage("opcode 0 is invalid (zero-filled space, as a crash can leave)")
        if opcode == Opcode.HEADER and offset != len(fmt.MAGIC):
            raise _Damage("a second header")
        if opcode in (Opcode.SCHEMA, Opcode.CHANNEL, Opcode.MESSAGE):
            _data_record(opcode, body, r.schemas, r.channels, r.messages)
            r.top_level_messages += int(opcode == Opcode.MESSAGE)
        elif opcode == Opcode.CHUNK:
            self._chunk(offset, body)
            self._after_chunk = True
        elif opcode == Opcode.MESSAGE_INDEX and after_chunk:
            self._message_index(offset, body)
            self._after_chunk = True

    def _chunk(self, offset: int, body: bytes) -> None:
        """Take a chunk's records only if all of them are intact."""
        r = self._r
        rec = fmt.parse_chunk(body)
        schemas, channels = dict(r.schemas), dict(r.channels)
        messages: list[fmt.MessageRecord] = []
        indexes: dict[int, list[tuple[int, int]]] = {}
        inner_end = 0
        for inner_offset, opcode, inner in fmt.iter_records(rec.data):
            inner_end = inner_offset + fmt.RECORD_HEAD.size + len(inner)
            if opcode in (Opcode.SCHEMA, Opcode.CHANNEL, Opcode.MESSAGE):
                _data_record(opcode, inner, schemas, channels, messages)
            if opcode == Opcode.MESSAGE:
                msg = messages[-1]
                indexes.setdefault(msg.channel_id, []).append((msg.log_time, inner_offset))
        if inner_end != len(rec.data):
            raise _Damage("its content ends inside a record")
        r.schemas, r.channels = schemas, channels
        r.messages.extend(messages)
        r.chunk_indexes.append(
            fmt.ChunkIndexRecord(
                message_start_time=rec.message_start_time,
                message_end_time=rec.message_end_time,
                chunk_start_offset=offset,
                chunk_length=fmt.RECORD_HEAD.size + len(body),
                message_index_offsets=(),
                message_index_length=0,
                compression=rec.compression,
                compressed_size=len(body) - 40 - len(rec.compression.encode()),
                uncompressed_size=rec.uncompressed_size,
            )
        )
        r.missing_indexes = indexes

    def _message_index(self, offset: int, body: bytes) -> None:
        r = self._r
        channel_id = fmt.Cursor(body).u16()
        last = r.chunk_indexes[-1]
        r.chunk_indexes[-1] = replace(
            last,
            message_index_offsets=(*last.message_index_offsets, (channel_id, offset)),
            message_index_length=last.message_index_length + fmt.RECORD_HEAD.size + len(body),
        )
        r.missing_indexes.pop(channel_id, None)


def _data_record(
    opcode: int,
    body: bytes,
    schemas: dict[int, fmt.SchemaRecord],
    channels: dict[int, fmt.ChannelRecord],
    messages: list[fmt.MessageRecord],
) -> None:
    """Check a schema, channel or message record against what came before and keep it."""
    if opcode == Opcode.MESSAGE:
        msg = fmt.parse_message(body)
        if msg.channel_id not in channels:
            raise _Damage(f"a message on channel {msg.channel_id}, which was never declared")
        messages.append(msg)
    elif opcode == Opcode.SCHEMA:
        schema = fmt.parse_schema(body)
        if schemas.setdefault(schema.id, schema) != schema:
            raise _Damage(f"schema {schema.id} is declared twice with different content")
    else:
        chan = fmt.parse_channel(body)
        if chan.schema_id and chan.schema_id not in schemas:
            raise _Damage(f"channel {chan.id} uses schema {chan.schema_id}, never declared")
        if channels.setdefault(chan.id, chan) != chan:
            raise _Damage(f"channel {chan.id} is declared twice with different content")


def _name(opcode: int) -> str:
    try:
        return Opcode(opcode).name.lower().replace("_", " ")
    except ValueError:
        return f"unknown (opcode {opcode:#04x})"
