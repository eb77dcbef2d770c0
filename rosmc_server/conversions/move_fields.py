"""A reorder's moves in a ``rosmc/MissionEvent``: two packed fields, or (old journals) messages.

Part of :mod:`rosmc_server.conversions`. A whole new order of 25,000 skills is 25,000
moves. As ``rosmc/SkillMove[]`` genpy makes, writes and reads an object per move, and so
does every subscriber of the events topic. As ``move_ids`` (the ids joined by line
breaks: a skill id holds none) and ``move_indexes`` (``uint32[]``), genpy writes and
reads each field in one call, and a reader splits the ids in one call, straight into
the core's :class:`~rosmc_server.core.model.moves.MoveList`. Recordings made before these
fields existed carry their moves in ``moves``, which is still read.

A whole new order in a ``ReorderSkills`` request travels the same way: its ``order``
may be one string of the ids joined by line breaks.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

from ..core.errors import InvalidRequest
from ..core.model.moves import MoveList, SkillMove, move_columns

SEPARATOR = "\n"


def moves_to_fields(moves: Sequence[SkillMove]) -> tuple[str, tuple[int, ...]] | None:
    """``move_ids`` and ``move_indexes`` of ``moves``; None if an id holds a line break
    (only an id that never passed the id check can: such moves travel as ``moves``).

    The indexes are a tuple, as genpy reads a ``uint32[]``: a message made here equals
    the same message read back.
    """
    ids, indexes = move_columns(moves)
    joined = SEPARATOR.join(ids)
    if joined.count(SEPARATOR) != max(len(ids) - 1, 0):
        return None
    return joined, tuple(indexes)


def moves_from_fields(msg: Any) -> Sequence[SkillMove] | None:
    """The moves an event message packs in ``move_ids`` and ``move_indexes``; None if
    it packs none (an old recording's message has no such fields)."""
    indexes = getattr(msg, "move_indexes", ())
    if not indexes:
        return None
    ids = msg.move_ids.split(SEPARATOR)
    if len(ids) != len(indexes):
        raise InvalidRequest(
            f"an event names {len(ids)} moved skills but gives {len(indexes)} indexes"
        )
    return MoveList(ids, indexes)


def order_to_field(order: Sequence[str]) -> list[str]:
    """``order`` as a ``ReorderSkills`` request's ``order``: its ids joined by line
    breaks in one string (as is if it has fewer than two ids or an id holds a break)."""
    joined = SEPARATOR.join(order)
    if len(order) < 2 or joined.count(SEPARATOR) != len(order) - 1:
        return list(order)
    return [joined]


def order_from_field(order: Sequence[str]) -> Sequence[str]:
    """A ``ReorderSkills`` request's ``order`` as the ids it names (see
    :func:`order_to_field`); the core then checks them as any other order."""
    if len(order) == 1 and SEPARATOR in order[0]:
        return order[0].split(SEPARATOR)
    return order
