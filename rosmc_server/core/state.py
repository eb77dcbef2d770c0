"""The mission state: every agent's task, the barriers and the task markers.

:class:`MissionState` answers questions about the mission and changes only
through :meth:`MissionState.apply`, so every change is a :class:`Change`
that can be journaled and replayed.
"""

from __future__ import annotations

import bisect
from collections.abc import Iterable, Iterator, Sequence
from fractions import Fraction

from .changes import Change, SkillMove, moves_between
from .content import MissionContent as MissionContent
from .content import Sections as Sections
from .errors import NotFound
from .model import (
    Barrier,
    SkillInstance,
    SkillStatus,
    TaskMarker,
    Transfer,
    skill_id_of,
    skill_with,
)
from .pair_index import PairIndex
from .reorder import play_moves
from .validation import excerpt

# Spacing of the position keys given to a task's skills: room for 32 insertions at one
# place before the task's keys are spread again.
_KEY_SPACING = 1 << 32
# From this many moves on, a reorder is decoded in one pass over the stretch it touches
# (see :mod:`.reorder`) instead of shifting the task once per move.
BULK_MOVES = 16
_skill_id = skill_id_of


class MissionState:
    """Mission content plus lookup indexes; mutated only by :meth:`apply`.

    Every skill has a position key: the keys of a task increase along it, so a
    skill's index is a binary search away and the order of any two skills is a
    comparison. The barrier members of each task are kept sorted by key too, so
    the deadlock check looks at barrier members only. A change updates these
    indexes where it touched the task: its cost does not grow with the mission.
    """

    def __init__(self, content: MissionContent, revision: int = 0) -> None:
        self.revision = revision
        # Own copies: the state changes its content in place, and neither the
        # caller's content nor an event's replacement may change with it.
        self._content = content.copy()
        self._agent_of: dict[str, str] = {}
        self._barrier_of: dict[str, str] = {}
        self._bound: dict[str, set[str]] = {}
        self._key_of: dict[str, int] = {}
        self._keys: dict[str, list[int]] = {}  # per agent, parallel to its task
        self._member_keys: dict[str, list[int]] = {}  # per agent, its barrier members' keys
        self._member_ids: dict[str, list[str]] = {}  # ... and their ids, in task order
        self._in_transfer: dict[str, set[str]] = {}  # per agent, skills awaiting the robot
        self._pairs = PairIndex()  # barrier members by pair of agents they join
        # The last moves decoded and what they gave: planning, the undo history and
        # applying a reorder each ask for it within one commit (cleared by every change).
        self._played: tuple[Sequence[SkillMove], str, tuple[int, list[str]] | None] | None = None
        self._reindex()

    # -- queries ---------------------------------------------------------
    @property
    def library(self) -> str:
        """Name of the library the mission is written against."""
        return self._content.library

    @property
    def agents(self) -> tuple[str, ...]:
        """Agents that have a task, in library order."""
        return tuple(self._content.tasks)

    @property
    def barriers(self) -> Sequence[Barrier]:
        """All barriers, oldest first."""
        return tuple(self._content.barriers.values())

    @property
    def markers(self) -> Sequence[TaskMarker]:
        """All task markers, oldest first."""
        return tuple(self._content.markers.values())

    def content(self) -> MissionContent:
        """A copy of the content (safe to keep while the state changes)."""
        return self._content.copy()

    def task(self, agent: str) -> Sequence[SkillInstance]:
        """The ordered skills of ``agent``."""
        try:
            return self._content.tasks[agent]
        except KeyError:
            known = ", ".join(self._content.tasks) or "none"
            raise NotFound(
                f"agent {excerpt(agent)} has no task (agents with tasks: {known})"
            ) from None

    def skills(self) -> Iterator[SkillInstance]:
        """Every skill of every agent, task by task."""
        for task in self._content.tasks.values():
            yield from task

    @property
    def skill_count(self) -> int:
        """How many skills the mission holds."""
        return len(self._agent_of)

    def has_skill(self, skill_id: str) -> bool:
        """Whether a skill with this id exists."""
        return skill_id in self._agent_of

    def locate(self, skill_id: str) -> tuple[str, int]:
        """The agent and index of a skill; NotFound if there is none."""
        agent = self._agent_of.get(skill_id)
        if agent is None:
            raise NotFound(f"there is no skill {excerpt(skill_id)}")
        return agent, bisect.bisect_left(self._keys[agent], self._key_of[skill_id])

    def order_key(self, skill_id: str) -> int:
        """A number that grows along the skill's task: compares two skills of one task."""
        return self._key_of[skill_id]

    def partner_agents(self, agent: str) -> Iterable[str]:
        """The agents whose tasks share (or shared) a barrier with ``agent``'s."""
        return self._pairs.partners(agent)

    def first_shared_after(self, skill_id: str, other: str) -> str | None:
        """The first barrier member after ``skill_id`` on its task that shares a barrier
        with ``other``'s task (a binary search; see :mod:`.pair_index`)."""
        agent = self.agent_of(skill_id)
        return self._pairs.first_after(agent, other, self._key_of[skill_id])

    def agent_of(self, skill_id: str) -> str:
        """The agent whose task holds the skill; NotFound if there is none."""
        agent = self._agent_of.get(skill_id)
        if agent is None:
            raise NotFound(f"there is no skill {excerpt(skill_id)}")
        return agent

    def skill(self, skill_id: str) -> SkillInstance:
        """The skill with this id; NotFound if there is none."""
        agent, index = self.locate(skill_id)
        return self._content.tasks[agent][index]

    def pending(self, agent: str, transfer: Transfer) -> list[SkillInstance]:
        """``agent``'s skills awaiting the robot's answer to ``transfer``, in task order."""
        task = self.task(agent)
        waiting = sorted(self._in_transfer.get(agent, ()), key=self._key_of.__getitem__)
        skills = (task[self.locate(skill_id)[1]] for skill_id in waiting)
        return [skill for skill in skills if skill.transfer is transfer]

    def sections(self, agent: str) -> Sections:
        """Where ``agent``'s task splits into synchronized, uploading and editable parts."""
        task = self.task(agent)
        synced_end = 0
        while synced_end < len(task) and task[synced_end].status is not SkillStatus.IDLE:
            synced_end += 1
        editable_start = synced_end
        while editable_start < len(task) and task[editable_start].transfer is Transfer.UPLOADING:
            editable_start += 1
        return Sections(synced_end, editable_start)

    def barrier(self, barrier_id: str) -> Barrier:
        """The barrier with this id; NotFound if there is none."""
        try:
            return self._content.barriers[barrier_id]
        except KeyError:
            raise NotFound(f"there is no barrier {excerpt(barrier_id)}") from None

    def has_barrier(self, barrier_id: str) -> bool:
        """Whether a barrier with this id exists."""
        return barrier_id in self._content.barriers

    def barrier_of(self, skill_id: str) -> Barrier | None:
        """The barrier a skill belongs to, if any."""
        barrier_id = self._barrier_of.get(skill_id)
        return None if barrier_id is None else self._content.barriers[barrier_id]

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

    def order_after_moves(
        self, agent: str, moves: Sequence[SkillMove]
    ) -> tuple[int, list[str]] | None:
        """Where the stretch of ``agent``'s task that ``moves`` touch starts, and its ids
        after them; None unless the moves are canonical (see :func:`.reorder.play_moves`).

        Costs the stretch, once: nothing changes.
        """
        if self._played is not None and self._played[0] is moves and self._played[1] == agent:
            return self._played[2]
        played = self._order_after_moves(agent, moves)
        self._played = (moves, agent, played)
        return played

    def expect_moves(
        self, agent: str, moves: Sequence[SkillMove], start: int, order: Sequence[str]
    ) -> None:
        """Note that ``moves`` give ``agent``'s task from ``start`` on in ``order`` (the
        planner of a whole new order knows it), so that :meth:`order_after_moves` need
        not decode them. Nothing changes."""
        if len(moves) >= BULK_MOVES:
            self._played = (moves, agent, (start, list(order)))

    def _order_after_moves(
        self, agent: str, moves: Sequence[SkillMove]
    ) -> tuple[int, list[str]] | None:
        keys, key_of = self._keys[agent], self._key_of
        ids = [move.skill_id for move in moves]
        if set(map(self._agent_of.get, ids)) != {agent}:
            return None
        moved_keys = list(map(key_of.__getitem__, ids))
        targets = [move.index for move in moves]
        start = min(bisect.bisect_left(keys, min(moved_keys)), *targets)
        end = max(bisect.bisect_left(keys, max(moved_keys)), *targets) + 1
        if start < 0 or end > len(keys):
            return None
        stretch = list(map(_skill_id, self._content.tasks[agent][start:end]))
        order = play_moves(stretch, moves, start)
        return None if order is None else (start, order)

    def moves_for_order(self, agent: str, order: Sequence[str]) -> tuple[SkillMove, ...]:
        """The moves that give the last ``len(order)`` skills of ``agent``'s task ``order``."""
        task = self.task(agent)
        start = len(task) - len(order)
        return moves_between([skill.id for skill in task[start:]], order, start)

    def marker(self, name: str) -> TaskMarker:
        """The task marker called ``name``; NotFound if there is none."""
        try:
            return self._content.markers[name]
        except KeyError:
            raise NotFound(f"there is no task marker '{name}'") from None

    def has_marker(self, name: str) -> bool:
        """Whether a task marker called ``name`` exists."""
        return name in self._content.markers

    def bound_to(self, marker_name: str) -> list[SkillInstance]:
        """Skills with a parameter bound to the marker, in task order."""
        agents = {agent: rank for rank, agent in enumerate(self._content.tasks)}
        places = sorted(
            (agents[agent], index)
            for agent, index in map(self.locate, self._bound.get(marker_name, ()))
        )
        return [self._content.tasks[self.agents[rank]][index] for rank, index in places]

    # -- the one way to change -------------------------------------------
    def apply(self, change: Change) -> None:
        """Apply a change that the operations have validated (see :class:`Change`)."""
        try:
            self._apply(change)
        finally:
            self._played = None

    def _apply(self, change: Change) -> None:
        if change.replacement is not None:
            self._content = change.replacement.copy()
            self._reindex()
            return
        content = self._content
        for barrier_id in change.removed_barrier_ids:
            self._drop_barrier(barrier_id)
        for skill_id in change.removed_skill_ids:
            self._remove_skill(skill_id)
        for name in change.removed_marker_names:
            del content.markers[name]
        for placed in change.put_skills:
            self._put_skill(placed.index, placed.skill)
        if change.order_agent:
            moves = change.moves
            if not moves and change.blueprint_order:  # old journals: the whole new order
                moves = self.moves_for_order(change.order_agent, change.blueprint_order)
            self._move_skills(change.order_agent, moves)
        for barrier in change.put_barriers:
            self._drop_barrier(barrier.id)
            content.barriers[barrier.id] = barrier
            for skill_id in barrier.skill_ids:
                self._barrier_of[skill_id] = barrier.id
                self._add_member(skill_id)
        for marker in change.put_markers:
            content.markers[marker.name] = marker

    def _put_skill(self, index: int, skill: SkillInstance) -> None:
        task = self._content.tasks[skill.agent]
        if skill.id in self._agent_of:
            # Most puts replace the skill at the place they name (a synchronize of
            # thousands): only a stale place needs the binary search.
            fits = 0 <= index < len(task) and task[index].id == skill.id
            current = index if fits else self.locate(skill.id)[1]
            self._unbind(task[current])
            task[current] = skill
            self._note_transfer(skill)
        else:
            self._insert(skill.agent, index, skill)
        self._bind(skill)

    def _insert(self, agent: str, index: int, skill: SkillInstance) -> None:
        task, keys = self._content.tasks[agent], self._keys[agent]
        index = min(max(index, 0), len(task))
        low = keys[index - 1] if index else 0
        high = keys[index] if index < len(keys) else low + 2 * _KEY_SPACING
        if high - low < 2:  # no key left between the neighbours: spread the task's keys
            self._spread_keys(agent)
            low = keys[index - 1] if index else 0
            high = keys[index]
        key = (low + high) // 2
        task.insert(index, skill)
        keys.insert(index, key)
        self._key_of[skill.id] = key
        self._agent_of[skill.id] = agent
        self._note_transfer(skill)

    def _remove_skill(self, skill_id: str) -> SkillInstance:
        agent, index = self.locate(skill_id)
        self._remove_member(skill_id)
        skill = self._content.tasks[agent].pop(index)
        self._keys[agent].pop(index)
        del self._key_of[skill_id]
        del self._agent_of[skill_id]
        self._in_transfer.get(agent, set()).discard(skill_id)
        self._unbind(skill)
        return skill

    def _move_skill(self, skill_id: str, index: int) -> None:
        member = skill_id in self._barrier_of
        skill = self._remove_skill(skill_id)
        self._insert(skill.agent, index, skill)
        self._bind(skill)
        if member:
            self._add_member(skill_id)

    def _move_skills(self, agent: str, moves: Sequence[SkillMove]) -> None:
        played = self.order_after_moves(agent, moves) if len(moves) >= BULK_MOVES else None
        if played is None:
            for move in moves:
                self._move_skill(move.skill_id, move.index)
            return
        start, ids = played
        end = start + len(ids)
        task, keys, key_of = self._content.tasks[agent], self._keys[agent], self._key_of
        stretch = task[start:end]
        by_id = dict(zip(map(_skill_id, stretch), stretch, strict=True))  # in C, all at once
        task[start:end] = map(by_id.__getitem__, ids)
        low = keys[start - 1] if start else 0
        high = keys[end] if end < len(keys) else low + _KEY_SPACING * (len(ids) + 1)
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
        keys[:] = range(_KEY_SPACING, _KEY_SPACING * (len(task) + 1), _KEY_SPACING)
        self._key_of.update(zip(map(_skill_id, task), keys, strict=True))
        self._member_keys[agent] = [self._key_of[i] for i in self._member_ids.get(agent, [])]
        self._pairs.rekey(agent, self._key_of.__getitem__)

    def _drop_barrier(self, barrier_id: str) -> None:
        old = self._content.barriers.pop(barrier_id, None)
        if old is not None:
            for skill_id in old.skill_ids:
                self._remove_member(skill_id)
                self._barrier_of.pop(skill_id, None)

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

    def _note_transfer(self, skill: SkillInstance) -> None:
        waiting = self._in_transfer.setdefault(skill.agent, set())
        if skill.transfer is Transfer.NONE:
            waiting.discard(skill.id)
        else:
            waiting.add(skill.id)

    def _bind(self, skill: SkillInstance) -> None:
        for marker in skill.bindings.values():
            self._bound.setdefault(marker, set()).add(skill.id)

    def _unbind(self, skill: SkillInstance) -> None:
        for marker in skill.bindings.values():
            self._bound.get(marker, set()).discard(skill.id)

    def _reindex(self) -> None:
        self._agent_of.clear()
        self._barrier_of.clear()
        self._bound.clear()
        self._key_of.clear()
        self._keys.clear()
        self._member_keys.clear()
        self._member_ids.clear()
        self._in_transfer.clear()
        self._pairs.clear()
        for agent, task in self._content.tasks.items():
            self._keys[agent] = []
            self._spread_keys(agent)
            self._agent_of.update(dict.fromkeys(map(_skill_id, task), agent))
            for skill in task:
                if skill.bindings:
                    self._bind(skill)
                if skill.transfer is not Transfer.NONE:
                    self._note_transfer(skill)
        for barrier in self._content.barriers.values():
            for skill_id in barrier.skill_ids:
                self._barrier_of[skill_id] = barrier.id
                self._add_member(skill_id)


def with_status(skill: SkillInstance, status: SkillStatus, **changes: object) -> SkillInstance:
    """A copy of ``skill`` with a new status (and any other field changes)."""
    return skill_with(skill, status=status, **changes)
