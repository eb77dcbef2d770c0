"""Mission events as ROS 1 wire bytes, written once for the journal and the topic.

Part of :mod:`rosmc_server.conversions`. A whole-order reorder of 10,000 skills is an
event of 10,000 moves: as genpy messages it costs 10,000 ``rosmc/SkillMove`` objects, and
genpy serializes them twice (the journal's record, then the topic's publish), each time
in a Python loop. :class:`PackedEvent` is a ``rosmc/MissionEvent`` whose ``serialize``
writes bytes made once, with the moves written straight from the core's moves; every
other field is an ordinary genpy field (small: what one change puts or removes).

Used only while ``rosmc/MissionEvent`` is the definition it was written for (its
md5sum: ``moves`` and ``epoch`` are its last fields); otherwise :func:`packed_event`
gives the plain genpy message. A test checks the bytes against genpy's for random events.
"""

from __future__ import annotations

import struct
from collections.abc import Callable, Sequence
from dataclasses import replace
from typing import Any

import rosmc.msg as wire

from ..core import MissionEvent
from ..core.changes import SkillMove
from .mission import event_to_msg
from .packing import serialized, string_bytes

# The rosmc/MissionEvent definition PackedEvent writes (with its nested types).
PACKED_EVENT_MD5 = "ac4d4b26a525e4fbf93a677c9f22c326"

_COUNT = struct.Struct("<I")


class PackedEvent(wire.MissionEvent):  # type: ignore[misc]
    """A ``rosmc/MissionEvent`` that serializes as bytes made once, at construction.

    ``moves`` stays empty as a field: the core's moves are in ``core_moves`` and in the
    bytes. The other fields are set as usual (and must not change afterwards).
    """

    def __init__(self, event: MissionEvent, agent_of: Callable[[str], str], epoch: str) -> None:
        change = event.change
        plain = event_to_msg(replace(event, change=replace(change, moves=())), agent_of)
        plain.epoch = epoch
        super().__init__(**{name: getattr(plain, name) for name in plain.__slots__})
        self.core_moves: Sequence[SkillMove] = change.moves
        # genpy's bytes with no moves end in the moves' count (0) and the epoch.
        head = serialized(plain)
        tail = len(string_bytes(epoch))
        self.data = b"".join((head[: -tail - 4], moves_bytes(change.moves), head[-tail:]))

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


def moves_bytes(moves: Sequence[SkillMove]) -> bytes:
    """The wire bytes of a ``rosmc/SkillMove[]`` of ``moves``."""
    pack = _COUNT.pack
    parts = [pack(len(moves))]
    append = parts.append
    for move in moves:
        skill_id = move.skill_id.encode("utf-8")
        append(pack(len(skill_id)) + skill_id + pack(move.index))
    return b"".join(parts)
