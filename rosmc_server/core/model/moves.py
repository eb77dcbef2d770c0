"""Moves within a task: one move, and many moves held as two columns.

A whole new order of 25,000 skills is 25,000 moves. As 25,000 :class:`SkillMove`
objects they cost the planner, the wire and every reader of the event an object each;
:class:`MoveList` holds the same moves as two plain lists (the ids, the indexes) that
the planner writes, the state and the wire read, and that make a :class:`SkillMove`
only when one is asked for.
"""

from __future__ import annotations

from collections.abc import Iterator, Sequence
from dataclasses import dataclass
from typing import overload


@dataclass(frozen=True, slots=True)
class SkillMove:
    """Move a skill within its agent's task: ``index`` is its index once moved."""

    skill_id: str
    index: int


class MoveList(Sequence[SkillMove]):
    """Moves, applied one after the other, kept as two parallel lists.

    ``ids[k]`` moves to ``indexes[k]``. Reads as a sequence of :class:`SkillMove` and
    equals any sequence of the same moves. Neither list may change once given.
    """

    __slots__ = ("ids", "indexes")

    def __init__(self, ids: Sequence[str], indexes: Sequence[int]) -> None:
        if len(ids) != len(indexes):
            raise ValueError(f"{len(ids)} moved ids but {len(indexes)} indexes")
        self.ids = ids
        self.indexes = indexes

    def __len__(self) -> int:
        return len(self.ids)

    @overload
    def __getitem__(self, at: int) -> SkillMove: ...

    @overload
    def __getitem__(self, at: slice) -> MoveList: ...

    def __getitem__(self, at: int | slice) -> SkillMove | MoveList:
        if isinstance(at, slice):
            return MoveList(self.ids[at], self.indexes[at])
        return SkillMove(self.ids[at], self.indexes[at])

    def __iter__(self) -> Iterator[SkillMove]:
        return map(SkillMove, self.ids, self.indexes)

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, Sequence) or len(other) != len(self):
            return False
        ids, indexes = move_columns(other)
        return list(ids) == list(self.ids) and list(indexes) == list(self.indexes)

    def __hash__(self) -> int:
        return hash((tuple(self.ids), tuple(self.indexes)))

    def __repr__(self) -> str:
        shown = ", ".join(
            f"{i!r}->{n}" for i, n in zip(self.ids[:3], self.indexes[:3], strict=True)
        )
        more = f", ... {len(self) - 3} more" if len(self) > 3 else ""
        return f"MoveList([{shown}{more}])"


def move_columns(moves: Sequence[SkillMove]) -> tuple[Sequence[str], Sequence[int]]:
    """The moved ids and their indexes, as two sequences (a :class:`MoveList`'s own)."""
    if isinstance(moves, MoveList):
        return moves.ids, moves.indexes
    return [move.skill_id for move in moves], [move.index for move in moves]
