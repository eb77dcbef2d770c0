"""Journal records decoded on first use, and their leading fields read without decoding.

A 10,000-skill snapshot takes genpy about 0.3 s to decode, and a journal holds one
every 500 changes; a reader that decoded every record paid for every snapshot the
journal ever took. A :class:`JournalRecord` read from a journal keeps its payload
(a big one stays in the file, see :class:`~._mcap.deferred.DeferredMessage`) and decodes
it when :attr:`JournalRecord.message` is first asked for. Its leading fields (the
``revision``, ``stamp`` and ``kind`` that ``rosmc/Mission`` and ``rosmc/MissionEvent``
begin with, an event's ``agent`` and ``summary``) are read straight from the bytes,
so choosing which snapshot to start from and which events follow decodes nothing.
"""

from __future__ import annotations

import struct
from dataclasses import dataclass
from typing import Any

import genpy

from rosmc_server.recording._mcap import records as fmt
from rosmc_server.recording._mcap.codec import Decoder, RosMessage, installed_class
from rosmc_server.recording._mcap.deferred import DeferredMessage, payload_head
from rosmc_server.recording.errors import JournalError

KEEP_DECODED = 65536
"""A payload smaller than this keeps its decoded message (a snapshot is decoded anew)."""

_FIXED = {
    "bool": "<B",
    "uint8": "<B",
    "int8": "<b",
    "byte": "<b",
    "char": "<B",
    "uint16": "<H",
    "int16": "<h",
    "uint32": "<I",
    "int32": "<i",
    "float32": "<f",
    "uint64": "<Q",
    "int64": "<q",
    "float64": "<d",
    "time": "<II",
    "duration": "<ii",
}

_LAYOUTS = {type_: struct.Struct(layout) for type_, layout in _FIXED.items()}
"""Each fixed-size type's layout, compiled once (read for every record of a journal)."""


def leading_fields(definition: bytes) -> tuple[tuple[str, str], ...]:
    """The (type, name) of the fields a ROS 1 definition begins with, up to the first
    array or nested message (what can be read from the bytes without the rest)."""
    fields: list[tuple[str, str]] = []
    text = definition.decode(errors="replace").split("\n=====", 1)[0]
    for line in text.splitlines():
        words = line.split("#", 1)[0].split()
        if not words:
            continue
        if len(words) < 2 or "=" in line.split("#", 1)[0]:
            if "=" in line:
                continue  # a constant
            break
        type_, name = words[0], words[1]
        if type_ not in _FIXED and type_ != "string":
            break
        fields.append((type_, name))
    return tuple(fields)


def read_leading(fields: tuple[tuple[str, str], ...], data: bytes) -> dict[str, Any]:
    """The values of ``fields`` at the start of ``data``, as far as ``data`` holds them
    (as genpy gives them: ``time`` a ``genpy.Time``, strings decoded from UTF-8)."""
    values: dict[str, Any] = {}
    pos = 0
    for type_, name in fields:
        if type_ == "string":
            if pos + 4 > len(data):
                break
            (size,) = struct.unpack_from("<I", data, pos)
            if pos + 4 + size > len(data):
                break
            values[name] = data[pos + 4 : pos + 4 + size].decode("utf-8", "rosmsg")
            pos += 4 + size
            continue
        layout = _LAYOUTS[type_]
        if pos + layout.size > len(data):
            break
        unpacked = layout.unpack_from(data, pos)
        if type_ == "time":
            values[name] = genpy.Time(*unpacked)
        elif type_ == "duration":
            values[name] = genpy.Duration(*unpacked)
        else:
            values[name] = unpacked[0]
        pos += layout.size
    return values


class Leads:
    """The leading fields of each schema of one file, worked out once per schema."""

    def __init__(self) -> None:
        self._fields: dict[int, tuple[tuple[str, str], ...]] = {}

    def of(self, schema: fmt.SchemaRecord) -> tuple[tuple[str, str], ...]:
        """The leading fields of ``schema`` as the decoder will read them (none if the
        recorded definition may be a damaged copy of the installed one)."""
        found = self._fields.get(schema.id)
        if found is None:
            found = self._fields[schema.id] = _leads(schema)
        return found


def _leads(schema: fmt.SchemaRecord) -> tuple[tuple[str, str], ...]:
    recorded = leading_fields(schema.data)
    try:
        installed = str(installed_class(schema.name)._full_text).encode()
    except JournalError:
        return recorded
    if recorded == leading_fields(installed):
        return recorded
    # Perhaps a damaged copy of the installed definition, which the decoder then uses:
    # nothing is read from the bytes directly (every field is decoded).
    return () if len(schema.data) == len(installed) else recorded


@dataclass(frozen=True)
class Payload:
    """A recorded message's bytes and how to decode them."""

    decoder: Decoder
    schema: fmt.SchemaRecord
    record: fmt.MessageRecord
    leads: tuple[tuple[str, str], ...]

    @property
    def big(self) -> bool:
        """Whether its decoded message is not kept (it would hold megabytes)."""
        return isinstance(self.record, DeferredMessage) or len(self.record.data) >= KEEP_DECODED

    def decode(self) -> RosMessage:
        """The decoded message; raise JournalError if it does not decode (or is gone)."""
        return self.decoder.decode(self.schema, self.record.data)

    def leading(self) -> dict[str, Any]:
        """The leading fields the payload holds: all of them when it is in memory (an
        event's summary often ends past the head a deferred snapshot keeps)."""
        record = self.record
        data = payload_head(record) if isinstance(record, DeferredMessage) else record.data
        return read_leading(self.leads, data)


class JournalRecord:
    """One recorded message: its topic, log time (ns) and the decoded genpy message.

    A record read from a journal decodes its message on first use (and keeps it unless
    it is big: a snapshot is decoded anew each time). :attr:`revision`, :attr:`kind` and
    :meth:`field` read a ``rosmc/Mission`` or ``rosmc/MissionEvent``'s leading fields
    from its bytes without decoding it. Built with a message, it holds just that.

    Raises:
        JournalError: (from :attr:`message`) The payload does not decode, or its file
            no longer holds it.
    """

    __slots__ = ("_leading", "_message", "_payload", "log_time", "topic")

    def __init__(
        self,
        topic: str,
        log_time: int,
        message: RosMessage = None,
        payload: Payload | None = None,
    ) -> None:
        self.topic = topic
        self.log_time = log_time
        self._message = message
        self._payload = payload
        self._leading: dict[str, Any] | None = None

    @property
    def message(self) -> RosMessage:
        """The decoded message."""
        if self._message is not None or self._payload is None:
            return self._message
        message = self._payload.decode()
        if not self._payload.big:
            self._message = message
        return message

    @property
    def decoded(self) -> bool:
        """Whether the message is held decoded (asking for it costs nothing)."""
        return self._message is not None or self._payload is None

    def field(self, name: str) -> Any:
        """A leading field of the message, read from its bytes if it is not decoded.

        Raises:
            AttributeError: The message has no such field.
        """
        if self._payload is not None and self._message is None:
            if self._leading is None:
                self._leading = self._payload.leading()
            if name in self._leading:
                return self._leading[name]
        return getattr(self.message, name)

    def raw(self, cls: Any) -> bytes | None:
        """The message's bytes if it was recorded with the installed definition of the
        generated class ``cls`` (e.g. ``rosmc.msg.Mission``), else None."""
        payload = self._payload
        if payload is None or payload.schema.name != cls._type:
            return None
        if payload.schema.data != str(cls._full_text).encode():
            return None
        return payload.record.data

    @property
    def revision(self) -> int:
        """The ``revision`` of a snapshot or event."""
        return int(self.field("revision"))

    @property
    def kind(self) -> int:
        """The ``kind`` of an event."""
        return int(self.field("kind"))

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, JournalRecord):
            return NotImplemented
        return (self.topic, self.log_time, self.message) == (
            other.topic,
            other.log_time,
            other.message,
        )

    __hash__ = None  # type: ignore[assignment]  # compares by its (mutable) message

    def __repr__(self) -> str:
        shown = type(self.message).__name__ if self.decoded else "not decoded"
        return f"JournalRecord({self.topic!r}, {self.log_time}, {shown})"
