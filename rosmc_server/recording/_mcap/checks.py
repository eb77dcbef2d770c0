"""The schemas and channels an MCAP file declares, and the checks its records must pass.

A journal (an MCAP file whose header names :data:`~.channels.LIBRARY`) declares
its channels in a fixed order (:mod:`.layout`), so when the
declaration of a channel or schema is lost to damage, the scan can still tell
what a message on it is instead of losing every later message of the channel.
"""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

from mcap.opcode import Opcode

from rosmc_server.recording._mcap import layout
from rosmc_server.recording._mcap import records as fmt
from rosmc_server.recording.channels import JOURNAL_TOPICS


class RecordDamage(Exception):
    """A record that is complete by its length but cannot be what it claims to be."""


class Declarations:
    """Schemas and channels declared so far (the dicts given, updated in place).

    Args:
        schemas: Schema records by id.
        channels: Channel records by id.
        journal: Whether the file is a journal (see the module docstring).
    """

    def __init__(
        self,
        schemas: dict[int, fmt.SchemaRecord],
        channels: dict[int, fmt.ChannelRecord],
        journal: bool,
    ) -> None:
        self.schemas = schemas
        self.channels = channels
        self._journal = journal
        self._fixed: tuple[dict[int, fmt.SchemaRecord], dict[int, fmt.ChannelRecord]] | None = None
        self._taken: dict[int, int] = {}  # messages taken per channel
        self._rebuilt: list[str] = []

    def take(self, opcode: int, body: bytes, messages: list[fmt.MessageRecord]) -> bool:
        """Check a schema, channel or message record and keep it; True for a message.

        Raises:
            RecordDamage: It contradicts what came before.
            FormatError: Its fields do not fit in it.
        """
        if opcode == Opcode.MESSAGE:
            msg = fmt.parse_message(body)
            if msg.channel_id not in self.channels and not self._rebuild(msg.channel_id):
                raise RecordDamage(
                    f"a message on channel {msg.channel_id}, which was never declared"
                )
            messages.append(msg)
            self._taken[msg.channel_id] = self._taken.get(msg.channel_id, 0) + 1
            return True
        if opcode == Opcode.SCHEMA:
            schema = fmt.parse_schema(body)
            if self.schemas.setdefault(schema.id, schema) != schema:
                raise RecordDamage(f"schema {schema.id} is declared twice with different content")
            return False
        chan = fmt.parse_channel(body)
        if self._journal and chan.topic not in JOURNAL_TOPICS:
            raise RecordDamage(f"a channel {chan.topic!r}, which a journal does not have")
        known = not chan.schema_id or chan.schema_id in self.schemas
        if not known and not self._rebuild_schema(chan.schema_id):
            raise RecordDamage(f"channel {chan.id} uses schema {chan.schema_id}, never declared")
        if self.channels.setdefault(chan.id, chan) != chan:
            raise RecordDamage(f"channel {chan.id} is declared twice with different content")
        return False

    def forget(self, message: fmt.MessageRecord) -> None:
        """Take back the last message taken (it turned out to be damaged)."""
        self._taken[message.channel_id] -= 1

    def fits(self, channel_id: int, sequence: int) -> bool:
        """Whether a bare message with this channel and sequence number could be next.

        A journal numbers the messages of each channel 0, 1, 2, ... in its file: after
        damage, a message's number is at least the count of those taken before it.
        """
        if channel_id not in self.channels and channel_id not in self._fixed_channels():
            return False
        return not self._journal or sequence >= self._taken.get(channel_id, 0)

    @contextmanager
    def staged(self) -> Iterator[None]:
        """Undo every declaration made inside the block if it raises (a damaged chunk)."""
        schemas, channels = dict(self.schemas), dict(self.channels)
        taken, rebuilt = dict(self._taken), list(self._rebuilt)
        try:
            yield
        except BaseException:
            self.schemas.clear()
            self.schemas.update(schemas)
            self.channels.clear()
            self.channels.update(channels)
            self._taken, self._rebuilt = taken, rebuilt
            raise

    def notes(self, path: Path) -> list[str]:
        """One sentence per channel rebuilt from the fixed list."""
        return [
            f"journal {path}: the declaration of {what} is damaged; it was rebuilt from the "
            "journal's fixed channel list"
            for what in self._rebuilt
        ]

    def _fixed_channels(self) -> dict[int, fmt.ChannelRecord]:
        if not self._journal:
            return {}
        if self._fixed is None:
            self._fixed = layout.journal_declarations()
        return self._fixed[1]

    def _rebuild(self, channel_id: int) -> bool:
        chan = self._fixed_channels().get(channel_id)
        # Unless the topic is declared under another id that carries messages (a damaged
        # id declares it under a number nothing uses).
        used = {c.topic for c in self.channels.values() if self._taken.get(c.id)}
        if chan is None or chan.topic in used:
            return False
        if chan.schema_id not in self.schemas and not self._rebuild_schema(chan.schema_id):
            return False
        self.channels[channel_id] = chan
        self._rebuilt.append(f"channel {channel_id} ({chan.topic})")
        return True

    def _rebuild_schema(self, schema_id: int) -> bool:
        self._fixed_channels()
        schema = None if self._fixed is None else self._fixed[0].get(schema_id)
        if schema is None:
            return False
        self.schemas[schema_id] = schema
        self._rebuilt.append(f"schema {schema_id} ({schema.name})")
        return True
