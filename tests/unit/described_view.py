"""A mission rebuilt from the applier's typed changes alone (a test helper, not a test).

What a view that reacts to :data:`~rosmc_server.core.live.updates.MirrorChange` values sees:
plain task lists and dicts, changed step by step as each value says, with no rule of the
core. It checks each value against what it holds (the ``old`` of a change is what was
there, at the index given), so a description that is wrong at any step fails there.
"""

from __future__ import annotations

from collections.abc import Iterable

from rosmc_server.core import Barrier, MissionState, SkillInstance, TaskMarker
from rosmc_server.core.live.updates import (
    BarrierPut,
    BarrierRemoved,
    MarkerPut,
    MarkerRemoved,
    MirrorChange,
    MissionReset,
    SkillAdded,
    SkillChanged,
    SkillRemoved,
    SkillsMoved,
)


class DescribedView:
    """Tasks, barriers and markers kept only from described changes."""

    def __init__(self, state: MissionState) -> None:
        self.tasks: dict[str, list[SkillInstance]] = {}
        self.barriers: dict[str, Barrier] = {}
        self.markers: dict[str, TaskMarker] = {}
        self.reset(state)

    def reset(self, state: MissionState) -> None:
        """Take the whole mission (a :class:`MissionReset`)."""
        self.tasks = {agent: list(state.task(agent)) for agent in state.agents}
        self.barriers = {b.id: b for b in state.barriers}
        self.markers = {m.name: m for m in state.markers}

    def take(self, changes: Iterable[MirrorChange]) -> None:
        """Apply described changes one after the other, checking each against the view."""
        for change in changes:
            self._take(change)

    def _take(self, change: MirrorChange) -> None:
        match change:
            case MissionReset(state):
                self.reset(state)
            case SkillAdded(skill, index):
                task = self.tasks[skill.agent]
                assert 0 <= index <= len(task), (index, len(task))
                task.insert(index, skill)
            case SkillChanged(old, new, index):
                assert self.tasks[new.agent][index] == old
                self.tasks[new.agent][index] = new
            case SkillRemoved(skill, index):
                assert self.tasks[skill.agent][index] == skill
                del self.tasks[skill.agent][index]
            case SkillsMoved(agent, moves):
                task = self.tasks[agent]
                for move in moves:
                    at = next(i for i, s in enumerate(task) if s.id == move.skill_id)
                    task.insert(move.index, task.pop(at))
            case BarrierPut(old, new):
                assert self.barriers.get(new.id) == old
                self.barriers[new.id] = new
            case BarrierRemoved(barrier):
                assert self.barriers.pop(barrier.id) == barrier
            case MarkerPut(old, new):
                assert self.markers.get(new.name) == old
                self.markers[new.name] = new
            case MarkerRemoved(marker):
                assert self.markers.pop(marker.name) == marker
            case _:
                raise AssertionError(f"not a change of the mission: {change!r}")

    def matches(self, state: MissionState) -> bool:
        """Whether the view holds exactly ``state``'s tasks, barriers and markers."""
        return (
            self.tasks == {agent: list(state.task(agent)) for agent in state.agents}
            and self.barriers == {b.id: b for b in state.barriers}
            and self.markers == {m.name: m for m in state.markers}
        )
