"""ROS 1 serialisation of journal messages and their schemas.

genpy and the generated ``rosmc.msg`` classes come without type information;
they are imported through ``importlib`` so that only this module deals in
``Any``. A recorded message decodes into the installed generated class when
the recorded definition is the installed one (so it compares equal to messages
the server builds), and otherwise into a class generated from the definition
embedded in the journal, with a note saying so.
"""

import importlib
from collections.abc import Callable
from io import BytesIO
from typing import Any

from mcap.records import Schema
from mcap_ros1.decoder import DecoderFactory

from rosmc_server.recording._mcap import records as fmt
from rosmc_server.recording.channels import JOURNAL_TOPICS, SCHEMA_ENCODING
from rosmc_server.recording.errors import JournalError

RosMessage = Any
"""A genpy message instance (generated classes carry no type information)."""

_genpy = importlib.import_module("genpy")
_genmsg = importlib.import_module("genmsg")
MessageException: type[Exception] = _genpy.MessageException
"""genpy's root of (de)serialisation errors."""
DefinitionErrors: tuple[type[Exception], ...] = (
    _genmsg.InvalidMsgSpec,
    _genmsg.MsgNotFound,
    _genmsg.MsgGenerationException,
)
"""What genmsg raises for a message definition it cannot parse."""


def serialize(msg: RosMessage) -> bytes:
    """Return the ROS 1 wire bytes of ``msg``; raise JournalError if it cannot be encoded."""
    buffer = BytesIO()
    try:
        msg.serialize(buffer)
    except MessageException as err:
        raise JournalError(f"cannot serialise a {msg._type} message: {err}") from err
    return buffer.getvalue()


def schema_of(type_name: str) -> bytes:
    """Return the full ``ros1msg`` definition of an installed type, e.g. ``rosmc/Mission``."""
    return str(installed_class(type_name)._full_text).encode()


def installed_class(type_name: str) -> Any:
    """Return the generated class of ``pkg/Type``; raise JournalError if it is not installed."""
    package, _, name = type_name.partition("/")
    try:
        cls = getattr(importlib.import_module(f"{package}.msg"), name)
    except (ImportError, AttributeError) as err:
        raise JournalError(f"message type {type_name} is not installed: {err}") from err
    return cls


def is_installed(schema: fmt.SchemaRecord) -> bool:
    """Whether ``schema`` is the installed definition of its type, word for word (the
    generated class then decodes whatever was serialized with it)."""
    try:
        cls = installed_class(schema.name)
    except JournalError:
        return False
    return schema.encoding == SCHEMA_ENCODING and str(cls._full_text).encode() == schema.data


# genpy generates Python source from a recorded definition and imports it, so a damaged
# definition fails in whatever way that source fails; so may decoding with it.
_GENERATION_ERRORS: tuple[type[Exception], ...] = (
    *DefinitionErrors,
    SyntaxError,
    ValueError,
    KeyError,
    IndexError,
    AttributeError,
    TypeError,
)
_DECODING_ERRORS: tuple[type[Exception], ...] = (
    MessageException,
    ValueError,
    IndexError,
    TypeError,
    AttributeError,
)


class Decoder:
    """Decodes message payloads per schema; collects notes about how it had to decode."""

    def __init__(self) -> None:
        self._decoders: dict[int, Callable[[bytes], RosMessage]] = {}
        self._dynamic = DecoderFactory()
        self.notes: list[str] = []

    def decode(self, schema: fmt.SchemaRecord, data: bytes) -> RosMessage:
        """Decode ``data``; raise JournalError if the schema or the bytes do not fit.

        Data that the recorded definition cannot decode gets a second chance with the
        installed definition of that name: the recorded text may be what is damaged.
        """
        decoder = self._decoders.get(schema.id)
        if decoder is None:
            decoder = self._decoders[schema.id] = self._make(schema)
        try:
            return decoder(data)
        except _DECODING_ERRORS as err:
            installed = self._installed(schema)
            if installed is not None and installed is not decoder:
                try:
                    return installed(data)
                except MessageException:
                    pass
            raise JournalError(f"a {schema.name} message does not decode: {err}") from err

    def _installed(self, schema: fmt.SchemaRecord) -> Callable[[bytes], RosMessage] | None:
        """A decoder with the installed class of the schema's name, if there is one."""
        cls = _installed_class_of(schema.name)
        if cls is None:
            return None
        decoder: Callable[[bytes], RosMessage] = lambda data: cls().deserialize(data)  # noqa: E731
        return decoder

    def _make(self, schema: fmt.SchemaRecord) -> Callable[[bytes], RosMessage]:
        installed = self._installed(schema)
        cls = _installed_class_of(schema.name)
        text = b"" if cls is None else str(cls._full_text).encode()
        if installed is not None and text == schema.data and cls._type == schema.name:
            return installed
        if installed is not None and (
            schema.encoding != SCHEMA_ENCODING or _damaged_copy(schema.data, text)
        ):
            self.notes.append(
                f"the recorded schema of {schema.name} is damaged (a few bytes differ from the "
                "installed definition); its messages were decoded with the installed one"
            )
            return installed
        if schema.encoding != SCHEMA_ENCODING:
            raise JournalError(
                f"schema {schema.name} has encoding {schema.encoding!r}, not ros1msg"
            )
        mcap_schema = Schema(
            id=schema.id, name=schema.name, encoding=schema.encoding, data=schema.data
        )
        try:
            decoder = self._dynamic.decoder_for("ros1", mcap_schema)
        except _GENERATION_ERRORS as err:
            if installed is None:
                raise JournalError(
                    f"the recorded definition of {schema.name} is invalid: {err}"
                ) from err
            self.notes.append(
                f"the recorded definition of {schema.name} is invalid ({err}); its messages "
                "were decoded with the installed one"
            )
            return installed
        if decoder is None:
            raise JournalError(f"no ROS 1 decoder for schema {schema.name}")
        self.notes.append(
            f"the recorded definition of {schema.name} differs from the installed one "
            "(or none is installed); its messages were decoded with the recorded definition"
        )
        return decoder


DAMAGE_LIMIT = 8
"""Bytes in which a recorded definition may differ from the installed one of the same length
and still count as a damaged copy of it (an edited definition changes its length)."""


def _damaged_copy(recorded: bytes, installed: bytes, limit: int = DAMAGE_LIMIT) -> bool:
    """Whether ``recorded`` is ``installed`` with at most ``limit`` bytes damaged."""
    if len(recorded) != len(installed):
        return False
    return sum(a != b for a, b in zip(recorded, installed, strict=True)) <= limit


def _installed_class_of(name: str) -> Any:
    """The installed class of the type ``name``, or of the journal type whose name it is
    a damaged copy of (one or two characters differ); None if there is none."""
    try:
        return installed_class(name)
    except JournalError:
        pass
    for journal_type in set(JOURNAL_TOPICS.values()):
        if _damaged_copy(name.encode(), journal_type.encode(), limit=2):
            return installed_class(journal_type)
    return None
