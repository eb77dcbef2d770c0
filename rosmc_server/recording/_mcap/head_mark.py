"""The journal's own copy of its revision mark, in two slots at the head of every file.

The revision mark (:mod:`rosmc_server.recording.high_water`) is what keeps a revision
number from being handed out twice after a journal lost its end. Kept only in the side
file ``<journal>.revisions``, it is lost with that file (a copy of the ``.mcap`` alone, a
restored directory), and a journal that also lost its end would then hand out numbers
operators already saw. So every part file carries the mark too, at its head, where a
journal cut short or zeroed from some point on still holds it.

Layout: right after the MCAP header, one Metadata record named :data:`NAME` whose map
holds a padding entry and two fixed-size slots, ``a`` and ``b``. Each slot's value starts
on its own 512-byte sector (:data:`SECTOR`), so a write torn by a power loss damages at
most the slot being written, never the header or the other slot. The writer rewrites
the slots in place with ``pwrite`` (the record's length never changes, so the file stays
valid MCAP), alternating between them; each slot is one line of JSON padded with spaces::

    {"seq": 41, "epoch": "3f9a01c2", "revision": 8000, "high_water": 8500, "crc": 1234}

The slots of the part being written and of the journal's first file
(:class:`FirstFileHead`) hold the same mark. ``seq`` counts the writes (the newer slot
wins) and ``crc`` is the CRC-32 of the line without it, so a slot torn or damaged is
recognised and the other one used. A reader finds the slots by their sector, without
parsing the header: a damaged header does not hide the mark.
"""

from __future__ import annotations

import json
import logging
import os
import zlib
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path

from mcap.opcode import Opcode

from rosmc_server.recording._mcap import records as fmt
from rosmc_server.recording.channels import LIBRARY, PROFILE

_log = logging.getLogger(__name__)

NAME = "rosmc/revisions"
"""The Metadata record's name."""
SECTOR = 512
"""Each slot's value starts on a multiple of this (a disk writes a sector whole or not)."""
SLOT_SIZE = SECTOR - 9  # the value, then the next entry's key: the next value starts a sector on
_KEY_AND_LENGTHS = 9  # u32 key length, one-letter key, u32 value length
HEAD_BYTES = 8 * SECTOR
"""Where a reader looks for the slots: the first bytes of a file."""


@dataclass(frozen=True)
class MarkRecord:
    """The Metadata record holding the slots, and where the slots' values lie in the file."""

    data: bytes
    slots: tuple[int, int]


def mark_record(start: int) -> MarkRecord:
    """The mark record to be written at file offset ``start``, its two slots blank."""
    before_map = start + fmt.RECORD_HEAD.size + 4 + len(NAME) + 4  # head, name, map length
    pad_entry_head = 4 + len("pad") + 4
    first = before_map + pad_entry_head + _KEY_AND_LENGTHS
    slot_a = -(-first // SECTOR) * SECTOR  # the first sector boundary after the fixed fields
    padding = slot_a - first
    entries = (
        _entry("pad", b" " * padding)
        + _entry("a", b" " * SLOT_SIZE)
        + _entry("b", b" " * SLOT_SIZE)
    )
    body = _string(NAME) + len(entries).to_bytes(4, "little") + entries
    data = fmt.record(Opcode.METADATA, body)
    return MarkRecord(data, (slot_a, slot_a + SECTOR))


def encode_slot(seq: int, fields: Mapping[str, str | int]) -> bytes:
    """The bytes of one slot: ``fields`` with ``seq`` and a CRC, padded to SLOT_SIZE."""
    body = {"seq": seq, **fields}
    crc = zlib.crc32(json.dumps(body, sort_keys=True).encode("ascii"))
    line = json.dumps({**body, "crc": crc}, sort_keys=True).encode("ascii")
    if len(line) > SLOT_SIZE:
        raise ValueError(f"a mark slot holds {SLOT_SIZE} bytes, this one needs {len(line)}")
    return line.ljust(SLOT_SIZE)


def decode_slot(data: bytes) -> dict[str, str | int] | None:
    """The fields of a slot (``seq`` included), or None if blank, torn or damaged."""
    try:
        fields = json.loads(data[:SLOT_SIZE].decode("ascii"))
    except (UnicodeDecodeError, ValueError):
        return None
    if not isinstance(fields, dict) or not isinstance(fields.get("seq"), int):
        return None
    crc = fields.pop("crc", None)
    if crc != zlib.crc32(json.dumps(fields, sort_keys=True).encode("ascii")):
        return None
    return fields


def read_slots(head: bytes) -> dict[str, str | int] | None:
    """The newest intact slot among the first bytes ``head`` of a file (None: none)."""
    best: dict[str, str | int] | None = None
    for offset in range(SECTOR, len(head) - SLOT_SIZE + 1, SECTOR):
        fields = decode_slot(head[offset : offset + SLOT_SIZE])
        if fields is not None and (best is None or int(fields["seq"]) > int(best["seq"])):
            best = fields
    return best


def slots_of(body: bytes, start: int) -> tuple[int, int] | None:
    """Where the slots of a mark record lie, given its body and the record's file offset
    (None if it is not a mark record of this layout)."""
    expected = mark_record(start)
    if len(body) != len(expected.data) - fmt.RECORD_HEAD.size:
        return None
    if not body.startswith(_string(NAME)):
        return None
    return expected.slots


def _string(text: str) -> bytes:
    data = text.encode("utf-8")
    return len(data).to_bytes(4, "little") + data


def _entry(key: str, value: bytes) -> bytes:
    return _string(key) + len(value).to_bytes(4, "little") + value


class FirstFileHead:
    """The mark slots of a journal's first file, rewritten while later parts are written.

    The first file is the one a person copies or restores; the part being written may be
    the one that is lost. So the mark goes to both heads.
    """

    def __init__(self, path: Path) -> None:
        """Open ``path`` to rewrite its slots; :attr:`slots` is None if it has none."""
        self.path = path
        self.slots: tuple[int, int] | None = None
        self._fd = -1
        try:
            with path.open("rb") as stream:
                head = stream.read(HEAD_BYTES)
            start = len(fmt.MAGIC) + len(fmt.header(PROFILE, LIBRARY))
            found = fmt.record_head(head, start)
            if found is not None and found[0] == Opcode.METADATA:
                body = head[start + fmt.RECORD_HEAD.size : start + fmt.RECORD_HEAD.size + found[1]]
                self.slots = slots_of(body, start)
            if self.slots is not None:
                self._fd = os.open(path, os.O_WRONLY | os.O_CLOEXEC)
        except OSError as err:
            _log.warning("journal %s: its head cannot keep the revision mark (%s)", path, err)
            self.slots = None

    def write(self, fields: Mapping[str, str | int], seq: int, sync: bool) -> None:
        """Rewrite the older slot (fdatasync if ``sync``); nothing if the file has no slots.

        Raises:
            OSError: The slot cannot be written.
        """
        if self.slots is None or self._fd < 0:
            return
        os.pwrite(self._fd, encode_slot(seq, fields), self.slots[seq % 2])
        if sync:
            os.fdatasync(self._fd)

    def close(self) -> None:
        """Close the file."""
        if self._fd >= 0:
            os.close(self._fd)
            self._fd = -1
