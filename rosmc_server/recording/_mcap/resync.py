"""Finding where records that can be trusted start again after damaged bytes.

After a damaged record the scan cannot trust any length field near it, so it
looks at every later byte that could be the opcode of a data record and asks
whether a record starting there holds up:

- a chunk when its content passes its CRC (whatever its own length field says);
- a bare schema, channel or message record when its fields fit what the file
  declared (a message's channel exists, its sequence number moves forward) and
  the next two records line up behind it;
- the Data End record when the summary's records follow it.

A message record inside an uncompressed chunk looks like a bare message, but a
message index, never a bare record, follows it: it does not line up.
"""

import re
from collections.abc import Callable

from mcap.opcode import Opcode

from rosmc_server.recording._mcap import records as fmt

KnownMessage = Callable[[int, int], bool]
"""(channel id, sequence) -> whether a bare message with them fits the file so far."""

_HEAD = fmt.RECORD_HEAD.size
_MIN_MESSAGE = 22  # channel, sequence, log time, publish time
_BARE = (Opcode.SCHEMA, Opcode.CHANNEL, Opcode.MESSAGE, Opcode.DATA_END)
_AFTER_DATA_END = frozenset(
    (
        Opcode.FOOTER,
        Opcode.SCHEMA,
        Opcode.CHANNEL,
        Opcode.CHUNK_INDEX,
        Opcode.ATTACHMENT_INDEX,
        Opcode.METADATA_INDEX,
        Opcode.STATISTICS,
        Opcode.SUMMARY_OFFSET,
    )
)
_CANDIDATES = {
    "chunked": re.compile(b"[\x06\x0f]"),
    "bare": re.compile(b"[\x03\x04\x05\x0f]"),
    "": re.compile(b"[\x03\x04\x05\x06\x0f]"),
}
_PLAUSIBLE_LENGTH = 1 << 32  # a record cut off at the end must still claim a sane length


class Resync:
    """Finds the next offset of ``data`` where a trustworthy record starts."""

    def __init__(self, data: bytes, known: KnownMessage) -> None:
        self._data = data
        self._known = known

    def find(self, start: int, stop: int, layout: str) -> int | None:
        """The first offset in [start, stop) where a trustworthy record starts.

        Args:
            layout: "chunked" or "bare" if the file so far holds that layout (only its
                records are looked for), "" if it is not known yet.
        """
        for match in _CANDIDATES[layout].finditer(self._data, start, stop):
            if self.trusted(match.start()):
                return match.start()
        return None

    def trusted(self, pos: int) -> bool:
        """Whether a record starting at ``pos`` holds up (see the module docstring)."""
        head = fmt.record_head(self._data, pos)
        if head is None:
            return False
        opcode, length = head
        end = pos + _HEAD + length
        if opcode == Opcode.CHUNK:
            chunk = self.chunk(pos)
            if chunk is None:
                return False
            # Without a CRC only a chunk whose head agrees with its content counts.
            return bool(chunk[0].uncompressed_crc) or (chunk[1] == end and self._lines_up(end, 1))
        if end > len(self._data):
            return False
        if opcode == Opcode.DATA_END:
            after = fmt.record_head(self._data, end)
            return length == 4 and (after is None or after[0] in _AFTER_DATA_END)
        return self._bare(pos, opcode, length) and self._lines_up(end, 2)

    def chunk(self, pos: int) -> tuple[fmt.ChunkRecord, int] | None:
        """The chunk whose body starts after the record head at ``pos``, by its own fields.

        Returns it and the offset where it ends, or None if no intact chunk is there.
        """
        try:
            return fmt.read_chunk(self._data, pos + _HEAD)
        except fmt.FormatError:
            return None

    def _bare(self, pos: int, opcode: int, length: int) -> bool:
        body = self._data[pos + _HEAD : pos + _HEAD + length]
        try:
            if opcode == Opcode.MESSAGE:
                message = fmt.parse_message(body)
                return self._known(message.channel_id, message.sequence)
            if opcode == Opcode.SCHEMA:
                schema = fmt.parse_schema(body)
                return schema.id > 0 and bool(schema.name)
            if opcode == Opcode.CHANNEL:
                return bool(fmt.parse_channel(body).topic)
        except fmt.FormatError:
            return False
        return False

    def _lines_up(self, pos: int, depth: int) -> bool:
        """Whether bare records follow from ``pos`` on (or the file ends there)."""
        data = self._data
        head = fmt.record_head(data, pos)
        if head is None:
            return True  # the end of the file, or a torn record head
        opcode, length = head
        if opcode not in _BARE:
            return False
        end = pos + _HEAD + length
        if end > len(data):
            return length < _PLAUSIBLE_LENGTH  # a record the crash cut short
        if opcode == Opcode.MESSAGE and not self._bare(pos, opcode, length):
            return False
        return depth <= 1 or opcode == Opcode.DATA_END or self._lines_up(end, depth - 1)
