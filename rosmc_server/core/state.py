"""The mission state: every agent's task, the barriers and the task markers.

:class:`MissionState` answers questions about the mission and changes only
through :meth:`MissionState.apply`, so every change is a :class:`Change`
that can be journaled and replayed.
"""

from __future__ import annotations

from collections.abc import Iterator, Sequence
from dataclasses import dataclass, field, replace

from .changes import Change
from .errors import NotFound
from .library import Library
from .model import Barrier, SkillInstance, SkillStatus, TaskMarker, Transfer
from .validation import excerpt


@dataclass
class MissionContent:
    """The content of a mission, without indexes: what files and snapshots hold."""

    library: str
    tasks: dict[str, list[SkillInstance]]
    barriers: dict[str, Barrier] = field(default_factory=dict)
    markers: dict[str, TaskMarker] = field(default_factory=dict)

    @classmethod
    def empty(cls, library: Library) -> MissionContent:
        """A mission with an empty task for every dynamic agent of ``library``."""
        return cls(library.name, {agent: [] for agent in library.dynamic_agents})

    def copy(self) -> MissionContent:
        """A copy whose tasks and mappings can change without touching this one."""
        return MissionContent(
            self.library,
            {agent: list(task) for agent, task in self.tasks.items()},
            dict(self.barriers),
            dict(self.markers),
        )


@dataclass(frozen=True)
class Sections:
    """Where an agent's task splits.

    ``task[:synced_end]`` is the synchronized section, ``task[synced_end:editable_start]``
    the blueprint skills being uploaded, ``task[editable_start:]`` the editable blueprint.
    """

    synced_end: int
    editable_start: int


class MissionState:
    """Mission content plus lookup indexes; mutated only by :meth:`apply`."""

    def __init__(self, content: MissionContent, revision: int = 0) -> None:
        self.revision = revision
        # Own copies: the state changes its content in place, and neither the
        # caller's content nor an event's replacement may change with it.
        self._content = content.copy()
        self._agent_of: dict[str, str] = {}
        self._barrier_of: dict[str, str] = {}
        self._bound: dict[str, set[str]] = {}
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

    def has_skill(self, skill_id: str) -> bool:
        """Whether a skill with this id exists."""
        return skill_id in self._agent_of

    def locate(self, skill_id: str) -> tuple[str, int]:
        """The agent and index of a skill; NotFound if there is none."""
        agent = self._agent_of.get(skill_id)
        if agent is None:
            raise NotFound(f"there is no skill {excerpt(skill_id)}")
        task = self._content.tasks[agent]
        for index, skill in enumerate(task):
            if skill.id == skill_id:
                return agent, index
        raise AssertionError(f"index out of date for skill {skill_id}")  # pragma: no cover

    def skill(self, skill_id: str) -> SkillInstance:
        """The skill with this id; NotFound if there is none."""
        agent, index = self.locate(skill_id)
        return self._content.tasks[agent][index]

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

    # -- the one way to change -------------------------------------------
    def apply(self, change: Change) -> None:
        """Apply a change that the operations have validated (see :class:`Change`)."""
        if change.replacement is not None:
            self._content = change.replacement.copy()
            self._reindex()
            return
        content = self._content
        for barrier_id in change.removed_barrier_ids:
            self._drop_barrier(barrier_id)
        for skill_id in change.removed_skill_ids:
            agent, index = self.locate(skill_id)
            self._unindex_skill(content.tasks[agent].pop(index))
        for name in change.removed_marker_names:
            del content.markers[name]
        for placed in change.put_skills:
            self._put_skill(placed.index, placed.skill)
        if change.order_agent:
            task = content.tasks[change.order_agent]
            by_id = {skill.id: skill for skill in task[len(task) - len(change.blueprint_order) :]}
            task[len(task) - len(change.blueprint_order) :] = [
                by_id[skill_id] for skill_id in change.blueprint_order
            ]
        for barrier in change.put_barriers:
            self._drop_barrier(barrier.id)
            content.barriers[barrier.id] = barrier
            for skill_id in barrier.skill_ids:
                self._barrier_of[skill_id] = barrier.id
        for marker in change.put_markers:
            content.markers[marker.name] = marker

    def _put_skill(self, index: int, skill: SkillInstance) -> None:
        task = self._content.tasks[skill.agent]
        if skill.id in self._agent_of:
            _, current = self.locate(skill.id)
            self._unindex_skill(task[current])
            task[current] = skill
        else:
            task.insert(index, skill)
        self._index_skill(skill)

    def _drop_barrier(self, barrier_id: str) -> None:
        old = self._content.barriers.pop(barrier_id, None)
        if old is not None:
            for skill_id in old.skill_ids:
                self._barrier_of.pop(skill_id, None)

    def _index_skill(self, skill: SkillInstance) -> None:
        self._agent_of[skill.id] = skill.agent
        for marker in skill.bindings.values():
            self._bound.setdefault(marker, set()).add(skill.id)

    def _unindex_skill(self, skill: SkillInstance) -> None:
        self._agent_of.pop(skill.id, None)
        for marker in skill.bindings.values():
            self._bound.get(marker, set()).discard(skill.id)

    def _reindex(self) -> None:
        self._agent_of.clear()
        self._barrier_of.clear()
        self._bound.clear()
        for skill in self.skills():
            self._index_skill(skill)
        for barrier in self._content.barriers.values():
            for skill_id in barrier.skill_ids:
                self._barrier_of[skill_id] = barrier.id


def with_status(skill: SkillInstance, status: SkillStatus, **changes: object) -> SkillInstance:
    """A copy of ``skill`` with a new status (and any other field changes)."""
    return replace(skill, status=status, **changes)  # type: ignore[arg-type]
