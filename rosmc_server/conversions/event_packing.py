"""Mission events as ROS 1 wire bytes, written once for the journal and the topic.

Part of :mod:`rosmc_server.conversions`. A synchronize of thousands of skills puts as
many ``rosmc/Skill``s: as genpy messages they cost an object tree each, and genpy
serializes them twice (the journal's record, then the topic's publish), each time in a
Python loop. :class:`PackedEvent` is a ``rosmc/MissionEvent`` whose ``serialize``
writes bytes made once, with the skills put written straight from the core's (through
:func:`~.packing.skill_bytes`); every other field is an ordinary genpy field (a
reorder's moves are two packed fields, see :mod:`.move_fields`).

Used only while ``rosmc/MissionEvent`` is the definition it was written for (its
md5sum: ``put_skills`` follows the summary); otherwise :func:`packed_event` gives the
plain genpy message. A test checks the bytes against genpy's for random events.
"""

from __future__ import annotations

import struct
from collections.abc import Callable, Sequence
from dataclasses import replace
from typing import Any

import rosmc.msg as wire

from ..core import MissionEvent
from ..core.model.changes import PlacedSkill
from .mission import event_to_msg
from .packing import serialized, skill_bytes, string_bytes

# The rosmc/MissionEvent definition PackedEvent writes (with its nested types).
PACKED_EVENT_MD5 = "b9c87033171a206238f41af42a33d931"

_COUNT = struct.Struct("<I")
_PUT_SKILLS_AT = 8 + 8 + 1  # revision, stamp and kind come before the agent and summary


class PackedEvent(wire.MissionEvent):  # type: ignore[misc]
    """A ``rosmc/MissionEvent`` that serializes as bytes made once, at construction.

    ``put_skills`` stays empty as a field: the core's are in ``core_put_skills`` and in
    the bytes. The other fields are set as usual (and must not change afterwards).
    """

    def __init__(self, event: MissionEvent, agent_of: Callable[[str], str], epoch: str) -> None:
        change = event.change
        plain = event_to_msg(replace(event, change=replace(change, put_skills=())), agent_of)
        plain.epoch = epoch
        super().__init__(**{name: getattr(plain, name) for name in plain.__slots__})
        self.core_put_skills: Sequence[PlacedSkill] = change.put_skills
        # genpy's bytes with no skills put: the skills' count (0) follows the summary.
        head = serialized(plain)
        put_at = _PUT_SKILLS_AT + len(string_bytes(plain.agent)) + len(string_bytes(plain.summary))
        self.data = b"".join(
            (head[:put_at], placed_skills_bytes(change.put_skills), head[put_at + 4 :])
        )

    def serialize(self, buff: Any) -> None:
        """Write the message's wire bytes to ``buff``."""
        buff.write(self.data)

    def __str__(self) -> str:
        return f"rosmc/MissionEvent revision {self.revision} ({len(self.data)} bytes, packed)"

    __repr__ = __str__


def packed_event(
    event: MissionEvent, agent_of: Callable[[str], str], epoch: str
) -> wire.MissionEvent:
    """``event`` as a message to journal and publish: a :class:`PackedEvent` while the
    definition is the one it writes, else ``event_to_msg`` with ``epoch`` set."""
    if wire.MissionEvent._md5sum != PACKED_EVENT_MD5:
        msg = event_to_msg(event, agent_of)
        msg.epoch = epoch
        return msg
    return PackedEvent(event, agent_of, epoch)


def placed_skills_bytes(placed: Sequence[PlacedSkill]) -> bytes:
    """The wire bytes of a ``rosmc/PlacedSkill[]`` of ``placed`` (a synchronize of
    thousands of skills puts each of them)."""
    pack = _COUNT.pack
    names: dict[str, bytes] = {}
    parts = [pack(len(placed))]
    for item in placed:
        parts += (pack(item.index), skill_bytes(item.skill, names))
    return b"".join(parts)
