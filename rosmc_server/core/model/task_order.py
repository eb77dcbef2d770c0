"""The order of every task: position keys, barrier members in task order, and reorders.

:class:`TaskOrder` is the part of :class:`.state.MissionState` that knows where each
skill stands: every skill has a position key (the keys of a task increase along it),
each task's barrier members are kept sorted by key, and a reorder of many moves is
decoded once into the new order of the stretch it touches and applied to that stretch
alone (see :mod:`.reorder`). The state owns the content; this class only reads the
tasks and keeps the keys in step with them.
"""

from __future__ import annotations

import bisect
from collections.abc import Iterable, Sequence
from fractions import Fraction

from ..errors import NotFound
from ..validation import excerpt
from .content import MissionContent
from .model import skill_id_of
from .moves import MoveList, SkillMove, move_columns
from .pair_index import PairIndex
from .reorder import canonical_moves, play_moves

# Spacing of the position keys given to a task's skills: room for 32 insertions at one
# place before the task's keys are spread again.
KEY_SPACING = 1 << 32
# From this many moves on, a reorder is decoded in one pass over the stretch it touches
# (see :mod:`.reorder`) instead of shifting the task once per move.
BULK_MOVES = 16
_skill_id = skill_id_of
# What decoding moves gave: where the stretch starts and its ids after them (None if
# the moves are not canonical).
Played = tuple[int, Sequence[str]] | None


class TaskOrder:
    """Position keys and barrier-member order of every task; reorders by stretch.

    The subclass sets ``_content`` and fills the indexes; this class keeps them in step
    when skills move.
    """

    _content: MissionContent

    def __init__(self) -> None:
        self._agent_of: dict[str, str] = {}
        self._barrier_of: dict[str, str] = {}
        self._key_of: dict[str, int] = {}
        self._keys: dict[str, list[int]] = {}  # per agent, parallel to its task
        self._member_keys: dict[str, list[int]] = {}  # per agent, its barrier members' keys
        self._member_ids: dict[str, list[str]] = {}  # ... and their ids, in task order
        self._pairs = PairIndex()  # barrier members by pair of agents they join
        # The last moves decoded and what they gave: planning, the undo history and
        # applying a reorder each ask for it within one commit (cleared by every change).
        self._played: tuple[Sequence[SkillMove], str, Played] | None = None

    def locate(self, skill_id: str) -> tuple[str, int]:
        """The agent and index of a skill; NotFound if there is none."""
        agent = self._agent_of.get(skill_id)
        if agent is None:
            raise NotFound(f"there is no skill {excerpt(skill_id)}")
        return agent, bisect.bisect_left(self._keys[agent], self._key_of[skill_id])

    def order_key(self, skill_id: str) -> int:
        """A number that grows along the skill's task: compares two skills of one task."""
        return self._key_of[skill_id]

    def agent_of(self, skill_id: str) -> str:
        """The agent whose task holds the skill; NotFound if there is none."""
        agent = self._agent_of.get(skill_id)
        if agent is None:
            raise NotFound(f"there is no skill {excerpt(skill_id)}")
        return agent

    def partner_agents(self, agent: str) -> Iterable[str]:
        """The agents whose tasks share (or shared) a barrier with ``agent``'s."""
        return self._pairs.partners(agent)

    def first_shared_after(self, skill_id: str, other: str) -> str | None:
        """The first barrier member after ``skill_id`` on its task that shares a barrier
        with ``other``'s task (a binary search; see :mod:`.pair_index`)."""
        agent = self.agent_of(skill_id)
        return self._pairs.first_after(agent, other, self._key_of[skill_id])

    def members_of(self, agent: str) -> tuple[str, ...]:
        """``agent``'s barrier members, in task order."""
        return tuple(self._member_ids.get(agent, ()))

    def members_around(self, skill_id: str) -> tuple[str | None, str | None]:
        """The barrier members just before and just after a skill on its agent's task.

        The skill itself, if a member, is neither. None where there is no such member.
        """
        agent = self.agent_of(skill_id)
        keys, ids = self._member_keys.get(agent, []), self._member_ids.get(agent, [])
        key = self._key_of[skill_id]
        at = bisect.bisect_left(keys, key)
        before = ids[at - 1] if at else None
        if at < len(keys) and keys[at] == key:
            at += 1
        return before, ids[at] if at < len(ids) else None

    def members_after_moves(self, agent: str, moves: Sequence[SkillMove]) -> list[str]:
        """``agent``'s barrier members in task order as they would be after ``moves``.

        Nothing changes: many moves are decoded at once (:meth:`order_after_moves`), a
        few are played on a copy of the task's keys.
        """
        members = self._member_ids.get(agent, [])
        played = self.order_after_moves(agent, moves) if len(moves) >= BULK_MOVES else None
        if played is not None:
            start, ids = played
            task_keys, member_keys = self._keys[agent], self._member_keys.get(agent, [])
            first = bisect.bisect_left(member_keys, task_keys[start])
            last = bisect.bisect_right(member_keys, task_keys[start + len(ids) - 1])
            inside = list(filter(self._barrier_of.__contains__, ids))
            return [*members[:first], *inside, *members[last:]]
        keys: list[int | Fraction] = list(self._keys[agent])
        moved: dict[str, int | Fraction] = {}
        for move in moves:
            key = moved.get(move.skill_id, self._key_of[move.skill_id])
            keys.pop(bisect.bisect_left(keys, key))
            index = min(max(move.index, 0), len(keys))
            # An exact key between the neighbours: a copy never needs spreading out.
            low = keys[index - 1] if index else (keys[0] - 2 if keys else 0)
            high = keys[index] if index < len(keys) else low + 2
            moved[move.skill_id] = Fraction(low + high, 2)
            keys.insert(index, moved[move.skill_id])
        return sorted(members, key=lambda skill_id: moved.get(skill_id, self._key_of[skill_id]))

    def order_after_moves(self, agent: str, moves: Sequence[SkillMove]) -> Played:
        """Where the stretch of ``agent``'s task that ``moves`` touch starts, and its ids
        after them; None unless the moves are canonical (see :func:`.reorder.play_moves`).

        Costs the stretch, once: nothing changes.
        """
        if self._played is not None and self._played[0] is moves and self._played[1] == agent:
            return self._played[2]
        played = self._order_after_moves(agent, moves)
        self._played = (moves, agent, played)
        return played

    def plan_order(self, agent: str, start: int, order: Sequence[str]) -> MoveList:
        """The fewest moves that give ``agent``'s task from ``start`` on ``order`` (a
        permutation of those skills' ids, else ValueError).

        The state remembers what they give, so that the deadlock check, the undo
        history and the apply of this commit need not decode them. Nothing changes.
        """
        current = list(map(_skill_id, self._content.tasks[agent][start:]))
        moves = MoveList(*canonical_moves(current, order, start))
        if len(moves) >= BULK_MOVES:
            self._played = (moves, agent, (start, order))
        return moves

    def _order_after_moves(self, agent: str, moves: Sequence[SkillMove]) -> Played:
        keys, key_of = self._keys[agent], self._key_of
        ids, targets = move_columns(moves)
        if set(map(self._agent_of.get, ids)) != {agent}:
            return None
        moved_keys = list(map(key_of.__getitem__, ids))
        start = min(bisect.bisect_left(keys, min(moved_keys)), *targets)
        end = max(bisect.bisect_left(keys, max(moved_keys)), *targets) + 1
        if start < 0 or end > len(keys):
            return None
        stretch = list(map(_skill_id, self._content.tasks[agent][start:end]))
        order = play_moves(stretch, moves, start)
        return None if order is None else (start, order)

    def _reorder_stretch(self, agent: str, start: int, ids: Sequence[str]) -> None:
        """Give ``agent``'s task from ``start`` on the order ``ids`` (of the same skills),
        with fresh keys for that stretch only."""
        end = start + len(ids)
        task, keys, key_of = self._content.tasks[agent], self._keys[agent], self._key_of
        stretch = task[start:end]
        by_id = dict(zip(map(_skill_id, stretch), stretch, strict=True))  # in C, all at once
        task[start:end] = map(by_id.__getitem__, ids)
        low = keys[start - 1] if start else 0
        high = keys[end] if end < len(keys) else low + KEY_SPACING * (len(ids) + 1)
        step = (high - low) // (len(ids) + 1)
        if step < 2:
            self._spread_keys(agent)
        else:
            keys[start:end] = range(low + step, low + step * (len(ids) + 1), step)
            key_of.update(zip(ids, keys[start:end], strict=True))
        members = self._member_ids.get(agent)
        if members:
            members.sort(key=key_of.__getitem__)
            self._member_keys[agent] = [key_of[skill_id] for skill_id in members]
            self._pairs.rekey(agent, key_of.__getitem__)

    def _spread_keys(self, agent: str) -> None:
        """Give ``agent``'s skills evenly spaced keys again (same order)."""
        task, keys = self._content.tasks[agent], self._keys[agent]
        keys[:] = range(KEY_SPACING, KEY_SPACING * (len(task) + 1), KEY_SPACING)
        self._key_of.update(zip(map(_skill_id, task), keys, strict=True))
        self._member_keys[agent] = [self._key_of[i] for i in self._member_ids.get(agent, [])]
        self._pairs.rekey(agent, self._key_of.__getitem__)

    def _add_member(self, skill_id: str) -> None:
        agent = self._agent_of.get(skill_id)
        if agent is None:
            return  # a barrier naming a skill that is not there (only a bad snapshot does)
        keys = self._member_keys.setdefault(agent, [])
        ids = self._member_ids.setdefault(agent, [])
        key = self._key_of[skill_id]
        at = bisect.bisect_left(keys, key)
        if at == len(keys) or keys[at] != key:
            keys.insert(at, key)
            ids.insert(at, skill_id)
        barrier = self._content.barriers.get(self._barrier_of.get(skill_id, ""))
        if barrier is not None:
            partners = (self._agent_of.get(member) for member in barrier.skill_ids)
            self._pairs.add(skill_id, agent, key, [a for a in partners if a is not None])

    def _remove_member(self, skill_id: str) -> None:
        agent = self._agent_of.get(skill_id)
        if agent is None:
            return
        self._pairs.remove(skill_id, self._key_of[skill_id])
        keys = self._member_keys.get(agent, [])
        at = bisect.bisect_left(keys, self._key_of[skill_id])
        if at < len(keys) and keys[at] == self._key_of[skill_id]:
            del keys[at]
            del self._member_ids[agent][at]
