"""The mission state: every agent's task, the barriers and the task markers.

:class:`MissionState` answers questions about the mission and changes only
through :meth:`MissionState.apply`, so every change is a :class:`Change`
that can be journaled and replayed.
"""

from __future__ import annotations

from collections.abc import Iterator, Sequence

from ..errors import NotFound
from ..validation import excerpt
from .changes import Change, ChangeObserver, SkillMove, moves_between
from .content import MissionContent as MissionContent
from .content import Sections as Sections
from .model import (
    Barrier,
    SkillInstance,
    SkillStatus,
    TaskMarker,
    Transfer,
    skill_id_of,
    skill_with,
)
from .task_order import BULK_MOVES as BULK_MOVES
from .task_order import KEY_SPACING, TaskOrder

_skill_id = skill_id_of


class MissionState(TaskOrder):
    """Mission content plus lookup indexes; mutated only by :meth:`apply`.

    Every skill has a position key: the keys of a task increase along it, so a
    skill's index is a binary search away and the order of any two skills is a
    comparison. The barrier members of each task are kept sorted by key too, so
    the deadlock check looks at barrier members only (see :class:`.TaskOrder`). A
    change updates these indexes where it touched the task: its cost does not grow
    with the mission.
    """

    def __init__(self, content: MissionContent, revision: int = 0) -> None:
        super().__init__()
        self.revision = revision
        # Own copies: the state changes its content in place, and neither the
        # caller's content nor an event's replacement may change with it.
        self._content = content.copy()
        self._bound: dict[str, set[str]] = {}
        self._in_transfer: dict[str, set[str]] = {}  # per agent, skills awaiting the robot
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

    def moves_for_order(self, agent: str, order: Sequence[str]) -> Sequence[SkillMove]:
        """The moves that give the last ``len(order)`` skills of ``agent``'s task ``order``."""
        task = self.task(agent)
        start = len(task) - len(order)
        return moves_between([skill.id for skill in task[start:]], order, start)

    # -- the one way to change -------------------------------------------
    def apply(self, change: Change, observer: ChangeObserver | None = None) -> None:
        """Apply a change that the operations have validated (see :class:`Change`).

        ``observer`` hears each step as it is made (nothing of a replacement: it is
        the whole mission).
        """
        try:
            self._apply(change, observer)
        finally:
            self._played = None

    def _apply(self, change: Change, observer: ChangeObserver | None) -> None:
        if change.replacement is not None:
            self._content = change.replacement.copy()
            self._reindex()
            return
        content = self._content
        for barrier_id in change.removed_barrier_ids:
            dropped = self._drop_barrier(barrier_id)
            if observer is not None and dropped is not None:
                observer.barrier_removed(dropped)
        for skill_id in change.removed_skill_ids:
            if observer is not None:
                observer.skill_removed(self.skill(skill_id), self.locate(skill_id)[1])
            self._remove_skill(skill_id)
        for name in change.removed_marker_names:
            removed = content.markers.pop(name)
            if observer is not None:
                observer.marker_removed(removed)
        for placed in change.put_skills:
            old, index = self._put_skill(placed.index, placed.skill)
            if observer is not None:
                observer.skill_put(old, placed.skill, index)
        if change.order_agent:
            moves = change.moves
            if not moves and change.blueprint_order:  # old journals: the whole new order
                moves = self.moves_for_order(change.order_agent, change.blueprint_order)
            self._move_skills(change.order_agent, moves)
            if observer is not None:
                observer.skills_moved(change.order_agent, moves)
        for barrier in change.put_barriers:
            replaced = self._drop_barrier(barrier.id)
            content.barriers[barrier.id] = barrier
            for skill_id in barrier.skill_ids:
                self._barrier_of[skill_id] = barrier.id
                self._add_member(skill_id)
            if observer is not None:
                observer.barrier_put(replaced, barrier)
        for marker in change.put_markers:
            replaced_marker = content.markers.get(marker.name)
            content.markers[marker.name] = marker
            if observer is not None:
                observer.marker_put(replaced_marker, marker)

    def _put_skill(self, index: int, skill: SkillInstance) -> tuple[SkillInstance | None, int]:
        """Insert or replace ``skill``; the skill it replaced (None) and where it is now."""
        task = self._content.tasks[skill.agent]
        old = None
        if skill.id in self._agent_of:
            # Most puts replace the skill at the place they name (a synchronize of
            # thousands): only a stale place needs the binary search.
            fits = 0 <= index < len(task) and task[index].id == skill.id
            index = index if fits else self.locate(skill.id)[1]
            old = task[index]
            self._unbind(old)
            task[index] = skill
            self._note_transfer(skill)
        else:
            index = self._insert(skill.agent, index, skill)
        self._bind(skill)
        return old, index

    def _insert(self, agent: str, index: int, skill: SkillInstance) -> int:
        task, keys = self._content.tasks[agent], self._keys[agent]
        index = min(max(index, 0), len(task))
        low = keys[index - 1] if index else 0
        high = keys[index] if index < len(keys) else low + 2 * KEY_SPACING
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
        return index

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
        else:
            self._reorder_stretch(agent, *played)

    def _drop_barrier(self, barrier_id: str) -> Barrier | None:
        old = self._content.barriers.pop(barrier_id, None)
        if old is not None:
            for skill_id in old.skill_ids:
                self._remove_member(skill_id)
                self._barrier_of.pop(skill_id, None)
        return old

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
