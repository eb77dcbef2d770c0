"""What the GUI shows of the mission, as immutable values taken from the mirror.

The mirror calls its listeners on ROS threads with its lock held; :func:`view_update` runs
there and copies only what an update touched (the tasks of the agents it changed, the
barriers or markers if they changed, the robot statuses that changed) into a
:class:`ViewUpdate`. That value then crosses to the GUI thread, where models apply it row
by row. No Qt and no rospy here, so it is tested without either.
"""

from __future__ import annotations

import time
from collections.abc import Iterable
from dataclasses import dataclass, field

from rosmc_server.core import AgentStatus, Barrier, MissionState, TaskMarker
from rosmc_server.core.legality import TaskView
from rosmc_server.core.updates import (
    AgentStatusChanged,
    BarrierPut,
    BarrierRemoved,
    MarkerPut,
    MarkerRemoved,
    MirrorUpdate,
    MissionReset,
    SkillAdded,
    SkillChanged,
    SkillRemoved,
    SkillsMoved,
)

AgentView = TaskView  # one robot's task as the panels show it (the rules read the same)


@dataclass(frozen=True)
class ViewUpdate:
    """What one mirror update changed, ready for the GUI thread.

    ``reset``: the whole mission was replaced; ``agents`` then holds every robot in order.
    Otherwise ``agents`` holds the robots whose task changed. ``barriers`` / ``markers``
    are every barrier / marker, or None if none changed. ``statuses`` are robot statuses
    that changed. ``changed_ids`` are the skills this update added, changed or moved.
    ``received`` is when the update reached this process (monotonic seconds).
    """

    revision: int
    reset: bool = False
    library: str = ""
    agents: tuple[AgentView, ...] = ()
    barriers: tuple[Barrier, ...] | None = None
    markers: tuple[TaskMarker, ...] | None = None
    statuses: tuple[AgentStatus, ...] = ()
    changed_ids: frozenset[str] = frozenset()
    summary: str = ""
    received: float = field(default_factory=time.monotonic)


def view_update(update: MirrorUpdate, state: MissionState | None) -> ViewUpdate:
    """Turn a mirror update into a :class:`ViewUpdate` (with the mirror's lock held)."""
    statuses = tuple(c.new for c in update.changes if isinstance(c, AgentStatusChanged))
    summary = update.event.summary if update.event is not None else ""
    if state is None:
        return ViewUpdate(update.revision, statuses=statuses)
    if any(isinstance(c, MissionReset) for c in update.changes):
        return ViewUpdate(
            update.revision,
            reset=True,
            library=state.library,
            agents=tuple(AgentView.of(state, agent) for agent in state.agents),
            barriers=tuple(state.barriers),
            markers=tuple(state.markers),
            statuses=statuses,
            summary=summary,
        )
    agents: list[str] = []
    changed: set[str] = set()
    barriers = markers = False
    for change in update.changes:
        if isinstance(change, (SkillAdded, SkillRemoved)):
            _add_once(agents, change.skill.agent)
            changed.add(change.skill.id)
        elif isinstance(change, SkillChanged):
            _add_once(agents, change.new.agent)
            changed.add(change.new.id)
        elif isinstance(change, SkillsMoved):
            _add_once(agents, change.agent)
            changed.update(move.skill_id for move in change.moves)
        elif isinstance(change, (BarrierPut, BarrierRemoved)):
            barriers = True
        elif isinstance(change, (MarkerPut, MarkerRemoved)):
            markers = True
    return ViewUpdate(
        update.revision,
        agents=tuple(AgentView.of(state, agent) for agent in agents if agent in state.agents),
        barriers=tuple(state.barriers) if barriers else None,
        markers=tuple(state.markers) if markers else None,
        statuses=statuses,
        changed_ids=frozenset(changed),
        summary=summary,
    )


def _add_once(items: list[str], item: str) -> None:
    if item not in items:
        items.append(item)


def barrier_tags(barriers: Iterable[Barrier]) -> dict[str, tuple[int, Barrier]]:
    """Each barrier member's skill id -> (barrier number from 1, barrier)."""
    tags: dict[str, tuple[int, Barrier]] = {}
    for number, barrier in enumerate(barriers, start=1):
        for skill_id in barrier.skill_ids:
            tags[skill_id] = (number, barrier)
    return tags
