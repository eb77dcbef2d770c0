"""Sequential, damage-tolerant scan of an MCAP file.

A journal whose writer was killed has no summary and may end inside a record; a
journal on a failing disk may hold damaged bytes anywhere. The scan therefore
never trusts the summary: it walks the records from the header on and keeps
every intact one. A record cut short by the end of the file ends the walk (a
torn tail, what a crash leaves). At a damaged record the scan searches forward
for the next record it can trust (:mod:`.resync`), notes the damaged byte range
and goes on, so one bad byte costs one record, not the rest of the file. A
chunk whose content passes its CRC is kept even when its opcode or length field
is damaged, and a bare message whose length field is damaged is cut back to
where the next record starts, so a wrong length never hides intact records.

What it found is everything the writer needs to continue the file (schemas,
channels, chunk indexes, statistics and the offset to continue at) and
everything the reader needs to decode the messages. A big message (a snapshot)
whose bytes a CRC vouches for, or that lies bare in the file, is not kept in
memory: it is a :class:`DeferredMessage`, read again from the file when its
``data`` is asked for, so a scan holds the file's small records only, however
many snapshots the file holds.
"""

from dataclasses import dataclass, field, replace
from pathlib import Path

from mcap.opcode import Opcode

from rosmc_server.recording._mcap import head_mark
from rosmc_server.recording._mcap import records as fmt
from rosmc_server.recording._mcap.checks import Declarations, RecordDamage
from rosmc_server.recording._mcap.deferred import DeferredMessage, PayloadSource
from rosmc_server.recording._mcap.journal_head import damaged_journal_head, read_journal_header
from rosmc_server.recording._mcap.resync import Resync
from rosmc_server.recording.channels import LIBRARY, PROFILE
from rosmc_server.recording.damage import Damage
from rosmc_server.recording.errors import JournalError

_HEAD = fmt.RECORD_HEAD.size
DEFER_BYTES = 65536
"""A message payload this big or bigger stays in the file (see :class:`DeferredMessage`)."""
_JOURNAL_OPCODES = frozenset(
    (
        Opcode.SCHEMA,
        Opcode.CHANNEL,
        Opcode.MESSAGE,
        Opcode.CHUNK,
        Opcode.MESSAGE_INDEX,
        Opcode.METADATA,
        Opcode.DATA_END,
        Opcode.FOOTER,
    )
)
"""What a JournalWriter writes after the header: anything else in a journal is damage."""


@dataclass
class ScanResult:
    """What a sequential scan found in an MCAP file (see module docstring)."""

    path: Path
    size: int
    profile: str
    library: str = ""
    schemas: dict[int, fmt.SchemaRecord] = field(default_factory=dict)
    channels: dict[int, fmt.ChannelRecord] = field(default_factory=dict)
    messages: list[fmt.MessageRecord] = field(default_factory=list)
    spans: list[tuple[int, int]] = field(default_factory=list)
    """Where each message's record (its chunk, if chunked) lies in the file, by message."""
    chunk_indexes: list[fmt.ChunkIndexRecord] = field(default_factory=list)
    missing_indexes: dict[int, list[tuple[int, int]]] = field(default_factory=dict)
    """Message indexes the last chunk should have but lacks (cut off after the chunk)."""
    top_level_messages: int = 0
    data_end: int = 0
    """Offset just after the last intact record of the data section: where to continue."""
    complete: bool = False
    dropped_bytes: int = 0
    """Bytes at the end that hold no intact record (a torn tail, an unfinished summary)."""
    warnings: list[str] = field(default_factory=list)
    damage: list[Damage] = field(default_factory=list)
    """Damaged byte ranges that were skipped, in file order."""
    mark_slots: tuple[int, int] | None = None
    """Where the revision mark's slots lie (:mod:`.head_mark`); None in older journals."""


class _Short(Exception):
    """A record that runs past the end of the file."""


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
    damaged_head = damaged_journal_head(path, data)
    if damaged_head is not None:
        profile, library, start, damage = PROFILE, LIBRARY, damaged_head.end, [damaged_head]
    elif data[: len(fmt.MAGIC)] != fmt.MAGIC[:size]:
        raise JournalError(f"{path} is not an MCAP file (it does not start with the MCAP magic)")
    else:
        profile, library, start, damage = read_journal_header(path, data)
    result = ScanResult(path=path, size=size, profile=profile, library=library)
    result.damage += damage
    _Walker(result, data).walk(start)
    return result


class _Walker:
    """Walks the records once, filling a ScanResult."""

    def __init__(self, result: ScanResult, data: bytes) -> None:
        self._r = result
        self._data = data
        self._journal = result.library == LIBRARY
        self._records = Declarations(result.schemas, result.channels, self._journal)
        self._resync = Resync(data, self._records.fits)
        self._in_summary = False
        self._stopped = False
        self._after_chunk = False  # message index records may follow a chunk
        self._last_bare: int | None = None  # start of the previous record, a bare message
        self._tail: int | None = None  # where the bytes at the end that hold no record start

    def walk(self, start: int) -> None:
        """Read every record; then set the data end, dropped bytes and warnings."""
        r = self._r
        pos = r.data_end = start
        while pos < r.size and not self._stopped and not r.complete:
            pos = self._summary(pos) if self._in_summary else self._data_record(pos)
        r.warnings += self._records.notes(r.path)
        if r.complete:
            return
        r.dropped_bytes = r.size - (r.size if self._tail is None else self._tail)
        if self._in_summary:
            self._warn(
                f"dropped the last {r.dropped_bytes} bytes (an unfinished summary written while "
                "closing; every data record is intact)"
            )
        elif r.dropped_bytes and not (r.damage and r.damage[-1].end == r.size):
            self._warn(f"dropped the last {r.dropped_bytes} bytes (a record cut short)")
        self._warn(f"was not closed cleanly (no footer); recovered {len(r.messages)} messages")

    def _warn(self, text: str) -> None:
        self._r.warnings.append(f"journal {self._r.path}: {text}")

    # -- the data section --------------------------------------------------------------
    def _data_record(self, pos: int) -> int:
        """Take the record at ``pos``; return where the next one starts."""
        last_bare, self._last_bare = self._last_bare, None
        try:
            end = self._read(pos)
        except _Short:
            return self._failed(pos, last_bare, "a record that runs past the end of the file")
        except (RecordDamage, fmt.FormatError) as err:
            return self._failed(pos, last_bare, f"a damaged {_name(self._data[pos])} ({err})")
        if not self._in_summary:
            self._r.data_end = end
        return end

    def _read(self, pos: int) -> int:
        head = fmt.record_head(self._data, pos)
        if head is None:
            raise _Short
        opcode, length = head
        end = pos + _HEAD + length
        if end > self._r.size:
            raise _Short
        self._record(pos, opcode, self._data[pos + _HEAD : end])
        return end

    def _record(self, offset: int, opcode: int, body: bytes) -> None:
        after_chunk, self._after_chunk = self._after_chunk, False
        r = self._r
        if not (after_chunk and opcode == Opcode.MESSAGE_INDEX):
            r.missing_indexes = {}  # message indexes belong right after their chunk
        if opcode == 0:
            raise RecordDamage("opcode 0 is invalid (zero-filled space, as a crash can leave)")
        if self._journal and opcode not in _JOURNAL_OPCODES:
            raise RecordDamage(f"opcode {opcode:#04x}, which a journal never writes")
        if opcode == Opcode.HEADER:
            raise RecordDamage("a second header")
        if opcode in (Opcode.SCHEMA, Opcode.CHANNEL, Opcode.MESSAGE):
            if self._records.take(opcode, body, r.messages):
                r.spans.append((offset, offset + _HEAD + len(body)))
                r.top_level_messages += 1
                self._last_bare = offset
                self._defer(offset, _HEAD + len(body))
        elif opcode == Opcode.CHUNK:
            self._chunk(offset, fmt.parse_chunk(body), _HEAD + len(body))
        elif opcode == Opcode.MESSAGE_INDEX and (after_chunk or self._journal):
            self._message_index(offset, body, after_chunk)
        elif opcode == Opcode.METADATA and self._journal:
            r.mark_slots = head_mark.slots_of(body, offset) or r.mark_slots
        elif opcode == Opcode.DATA_END:
            self._in_summary = True
            self._tail = offset
        elif opcode == Opcode.FOOTER:  # a summary-less file may omit Data End
            self._closing(offset + _HEAD + len(body))

    def _chunk(self, offset: int, rec: fmt.ChunkRecord, length: int) -> None:
        """Take a chunk's records only if all of them are intact."""
        r = self._r
        messages: list[fmt.MessageRecord] = []
        indexes: dict[int, list[tuple[int, int]]] = {}
        inner_end = 0
        with self._records.staged():
            for inner_offset, opcode, inner in fmt.iter_records(rec.data):
                inner_end = inner_offset + _HEAD + len(inner)
                if opcode in (Opcode.SCHEMA, Opcode.CHANNEL, Opcode.MESSAGE):
                    self._records.take(opcode, inner, messages)
                if opcode == Opcode.MESSAGE:
                    msg = messages[-1]
                    indexes.setdefault(msg.channel_id, []).append((msg.log_time, inner_offset))
                    if rec.uncompressed_crc:  # its CRC vouches for it when read again
                        self._defer_in(messages, offset, length, inner_offset + _HEAD + 22)
            if inner_end != len(rec.data):
                raise RecordDamage("its content ends inside a record")
        first = len(r.messages)
        r.messages.extend(messages)
        r.spans += [(offset, offset + length)] * (len(r.messages) - first)
        r.chunk_indexes.append(
            fmt.ChunkIndexRecord(
                message_start_time=rec.message_start_time,
                message_end_time=rec.message_end_time,
                chunk_start_offset=offset,
                chunk_length=length,
                message_index_offsets=(),
                message_index_length=0,
                compression=rec.compression,
                compressed_size=length - _HEAD - 40 - len(rec.compression.encode()),
                uncompressed_size=rec.uncompressed_size,
            )
        )
        r.missing_indexes = indexes
        self._after_chunk = True

    def _defer(self, record: int, length: int) -> None:
        """Leave the payload of the bare message just taken in the file if it is big."""
        self._defer_in(self._r.messages, record, length, record + _HEAD + 22, chunked=False)

    def _defer_in(
        self,
        messages: list[fmt.MessageRecord],
        record: int,
        length: int,
        start: int,
        chunked: bool = True,
    ) -> None:
        """Leave the payload of the last of ``messages`` in the file if it is big."""
        msg = messages[-1]
        if len(msg.data) >= DEFER_BYTES:
            source = PayloadSource(self._r.path, record, length, start, len(msg.data), chunked)
            messages[-1] = DeferredMessage(msg, source)

    def _message_index(self, offset: int, body: bytes, after_chunk: bool) -> None:
        r = self._r
        channel_id, entries, end = fmt.read_message_index(body, 0)
        if end != len(body):
            raise fmt.FormatError(f"its length field says {len(body)} bytes, its content {end}")
        if not after_chunk or r.missing_indexes.get(channel_id) != entries:
            raise RecordDamage("a message index that does not match the chunk before it")
        last = r.chunk_indexes[-1]
        r.chunk_indexes[-1] = replace(
            last,
            message_index_offsets=(*last.message_index_offsets, (channel_id, offset)),
            message_index_length=last.message_index_length + _HEAD + len(body),
        )
        r.missing_indexes.pop(channel_id, None)
        self._after_chunk = True

    # -- damage --------------------------------------------------------------------------
    def _failed(self, pos: int, last_bare: int | None, what: str) -> int:
        """Recover after the record at ``pos`` failed; return where to go on."""
        r = self._r
        kept = self._repaired_chunk(pos)
        if kept is not None:
            return kept
        if last_bare is not None:  # the message before may have a wrong length
            inside = self._resync.find(last_bare + _HEAD + 22, pos, "bare")
            if inside is not None:
                self._records.forget(r.messages.pop())
                r.spans.pop()
                r.top_level_messages -= 1
                return self._salvage_message(last_bare, inside, "length field")
        layout = "chunked" if r.chunk_indexes else "bare" if r.top_level_messages else ""
        found = self._resync.find(pos + 1, r.size, layout)
        if found is None:
            self._stopped = True
            self._tail = pos
            if not what.startswith("a record that runs past") and self._data[pos:].strip(b"\0"):
                r.damage.append(Damage(r.path, pos, r.size, what))  # else a torn tail
            return r.size
        head = fmt.record_head(self._data, pos)
        if head is not None and layout != "chunked":
            declared = pos + _HEAD + head[1]
            if head[0] == Opcode.MESSAGE and found < declared:
                return self._salvage_message(pos, found, "length field")
            if head[0] not in _JOURNAL_OPCODES and found == declared:
                return self._salvage_message(pos, found, "opcode")
        index = bool(head) and self._data[pos] == Opcode.MESSAGE_INDEX and bool(r.chunk_indexes)
        r.damage.append(Damage(r.path, pos, found, what, kept=index))
        return found

    def _repaired_chunk(self, pos: int) -> int | None:
        """Keep a chunk whose content passes its CRC though its record head is damaged."""
        r = self._r
        if r.top_level_messages:
            return None
        found = self._resync.chunk(pos)
        if found is None or not found[0].uncompressed_crc:
            return None
        rec, end = found
        try:
            self._chunk(pos, rec, end - pos)
        except (RecordDamage, fmt.FormatError):
            return None
        r.damage.append(Damage(r.path, pos, pos + _HEAD, "a damaged opcode or length field", True))
        r.data_end = end
        return end

    def _salvage_message(self, start: int, end: int, field_: str) -> int:
        """Take ``[start, end)`` as one bare message whose opcode or length is damaged."""
        r = self._r
        try:
            self._records.take(Opcode.MESSAGE, self._data[start + _HEAD : end], r.messages)
        except (RecordDamage, fmt.FormatError) as err:
            r.damage.append(Damage(r.path, start, end, f"a damaged message record ({err})"))
            return end
        r.spans.append((start, end))
        r.top_level_messages += 1
        where = (start, start + 1) if field_ == "opcode" else (start + 1, start + _HEAD)
        r.damage.append(Damage(r.path, *where, f"a damaged {field_}", kept=True))
        r.data_end = end
        self._last_bare = start
        return end

    # -- the summary ---------------------------------------------------------------------
    def _summary(self, pos: int) -> int:
        """Skip a summary record; the footer and closing magic end the file."""
        head = fmt.record_head(self._data, pos)
        end = pos + _HEAD + head[1] if head else self._r.size + 1
        if end > self._r.size:
            self._stopped = True
            return self._r.size
        if head is not None and head[0] == Opcode.FOOTER:
            self._closing(end)
        return end

    def _closing(self, footer_end: int) -> None:
        r = self._r
        magic = self._data[footer_end : footer_end + len(fmt.MAGIC)]
        if magic != fmt.MAGIC:
            self._in_summary = True  # counts as an unfinished summary
            self._stopped = True
            return
        r.complete = True
        trailing = r.size - footer_end - len(fmt.MAGIC)
        if trailing:
            self._warn(f"ignored {trailing} bytes after the end of the MCAP file")


def _name(opcode: int) -> str:
    try:
        return Opcode(opcode).name.lower().replace("_", " ") + " record"
    except ValueError:
        return f"record of unknown opcode {opcode:#04x}"
