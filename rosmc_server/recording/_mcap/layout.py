"""Which schemas and channels a journal declares, and with which ids.

A journal declares every channel of :data:`~..channels.JOURNAL_TOPICS` up front, in that
order, so its channel and schema ids follow from that list alone. The writer declares
them so (:meth:`.write.DataSection.journal`); the scan rebuilds a declaration lost to
damage from the same list (:class:`.checks.Declarations`).
"""

from __future__ import annotations

from collections.abc import Mapping

from rosmc_server.recording._mcap import records as fmt
from rosmc_server.recording._mcap.codec import schema_of
from rosmc_server.recording.channels import JOURNAL_TOPICS, MESSAGE_ENCODING, SCHEMA_ENCODING


def declare(
    schemas: dict[int, fmt.SchemaRecord],
    channels: dict[int, fmt.ChannelRecord],
    topics: Mapping[str, str],
) -> bytes:
    """Add each topic (name -> message type) not declared yet to ``schemas`` and ``channels``
    (updated in place, ids counting on from the highest); return the records declaring them."""
    records = b""
    declared = {c.topic for c in channels.values()}
    schema_ids = {s.name: s.id for s in schemas.values()}
    for topic, type_name in topics.items():
        if topic in declared:
            continue
        if type_name not in schema_ids:
            schema_id = schema_ids[type_name] = max(schemas, default=0) + 1
            schema = fmt.SchemaRecord(schema_id, type_name, SCHEMA_ENCODING, schema_of(type_name))
            schemas[schema_id] = schema
            records += fmt.schema(schema)
        channel_id = max(channels, default=0) + 1
        channel = fmt.ChannelRecord(channel_id, schema_ids[type_name], topic, MESSAGE_ENCODING)
        channels[channel_id] = channel
        records += fmt.channel(channel)
    return records


def journal_declarations() -> tuple[dict[int, fmt.SchemaRecord], dict[int, fmt.ChannelRecord]]:
    """The schemas and channels of a new journal, by id."""
    schemas: dict[int, fmt.SchemaRecord] = {}
    channels: dict[int, fmt.ChannelRecord] = {}
    declare(schemas, channels, JOURNAL_TOPICS)
    return schemas, channels
