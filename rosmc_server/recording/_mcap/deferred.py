"""Message payloads a scan leaves in the file, read back when they are asked for.

A journal's snapshots are megabytes each; a scan that kept them all in memory would cost the
whole history. A payload of :data:`.scan.DEFER_BYTES` or more is therefore kept as where it
lies (:class:`PayloadSource`) and its first :data:`HEAD_BYTES` (a snapshot's or event's
revision, stamp and kind): :class:`DeferredMessage` reads the rest, checked against its
chunk's CRC again, only when asked. Split from :mod:`.scan`.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from rosmc_server.recording._mcap import records as fmt
from rosmc_server.recording.errors import JournalError

_HEAD = fmt.RECORD_HEAD.size
HEAD_BYTES = 64
"""Bytes of a deferred payload kept in memory (its leading fields: revision, stamp, kind)."""


@dataclass(frozen=True)
class PayloadSource:
    """Where a deferred message's payload lies in its file.

    Attributes:
        path: The file.
        record: Offset of the record that holds it (a chunk, or the message itself).
        length: Bytes of that record, its opcode and length field included.
        start: Offset of the payload in the chunk's records (in the file, when bare).
        size: Bytes of the payload.
        chunked: Whether the record is a chunk (read and checked against its CRC again).
    """

    path: Path
    record: int
    length: int
    start: int
    size: int
    chunked: bool

    def load(self) -> bytes:
        """The payload's bytes; raise JournalError if the file no longer holds them."""
        try:
            with self.path.open("rb") as file:
                if not self.chunked:
                    file.seek(self.start)
                    data = file.read(self.size)
                else:
                    file.seek(self.record)
                    # By its own fields, as the scan kept it: its opcode or length may be
                    # damaged (a chunk its CRC vouches for is kept whole).
                    rec, _ = fmt.read_chunk(file.read(self.length), _HEAD)
                    data = rec.data[self.start : self.start + self.size]
        except (OSError, fmt.FormatError) as err:
            raise JournalError(
                f"journal {self.path} changed since it was read (byte {self.record}): {err}"
            ) from err
        if len(data) != self.size:
            raise JournalError(f"journal {self.path} changed since it was read: it is shorter")
        return data


class DeferredMessage(fmt.MessageRecord):
    """A Message record whose payload stays in the file until :attr:`data` is asked for.

    Compares, hashes and reads like a :class:`~.records.MessageRecord`; :attr:`head`
    holds the payload's first :data:`HEAD_BYTES` bytes, enough for a journal's reader
    to learn a snapshot's or event's revision without reading the rest.
    """

    head: bytes
    source: PayloadSource

    def __init__(self, msg: fmt.MessageRecord, source: PayloadSource) -> None:
        # Frozen fields, set as the dataclass's own __init__ sets them; data is not kept.
        for name in ("channel_id", "sequence", "log_time", "publish_time"):
            object.__setattr__(self, name, getattr(msg, name))
        object.__setattr__(self, "head", msg.data[:HEAD_BYTES])
        object.__setattr__(self, "source", source)

    @property  # the frozen base's read-only field, read from the file
    def data(self) -> bytes:
        """The payload, read from the file (and checked against its chunk's CRC) each time."""
        return self.source.load()


def payload_head(msg: fmt.MessageRecord) -> bytes:
    """The first bytes of a message's payload (at most :data:`HEAD_BYTES`), never from disk."""
    return msg.head if isinstance(msg, DeferredMessage) else msg.data[:HEAD_BYTES]
