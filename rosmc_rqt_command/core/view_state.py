"""What the GUI shows of the mission, as values taken from the mirror for the GUI thread.

The mirror calls its listeners on ROS threads with its lock held; :func:`view_update` runs
there and forwards what the mirror said changed: the event it applied, its skill deltas
(with indexes as the mirror applied them), the section bounds of the robots they touched,
the barriers or markers if they changed and the robot statuses that changed, as a
:class:`ViewUpdate`. Only a reset copies the mission (a state of the GUI's own). The
value then crosses to the GUI thread, where the view applies the event to its state with
the one applier (:func:`~rosmc_server.core.live.updates.apply_event`) and models change only
the rows the deltas name. No Qt and no rospy here, so it is tested without either.
"""

from __future__ import annotations

import time
from collections.abc import Iterable
from dataclasses import dataclass, field

from rosmc_server.core import (
    AgentStatus,
    Barrier,
    MissionEvent,
    MissionState,
    TaskMarker,
)
from rosmc_server.core.live.updates import (
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
from rosmc_server.core.model.moves import move_columns
from rosmc_server.core.rules.legality import TaskView

SkillDelta = SkillAdded | SkillChanged | SkillRemoved | SkillsMoved


@dataclass(frozen=True)
class TaskBounds:
    """Where a robot's task splits after an update (see :class:`TaskView`)."""

    agent: str
    synced_end: int
    editable_start: int
    uploading: bool = False
    removing: bool = False

    @classmethod
    def of(cls, state: MissionState, agent: str) -> TaskBounds:
        """``agent``'s bounds in ``state`` (call with the mirror's lock held)."""
        live = TaskView.live(state, agent)
        return cls(agent, live.synced_end, live.editable_start, live.uploading, live.removing)


@dataclass(frozen=True)
class ViewUpdate:
    """What one mirror update changed, ready for the GUI thread.

    ``reset``: the whole mission was replaced; ``state`` is then a copy of it for the GUI
    thread alone and ``agents`` every robot's task in it. Otherwise ``event`` is the event
    the mirror applied (None: robot statuses only), ``deltas`` the skill changes it made,
    in order, and ``bounds`` the sections of each robot they touched. ``barriers`` /
    ``markers`` are every barrier / marker, or None if none changed. ``statuses`` are
    robot statuses that changed. ``changed_ids`` are the skills this update added, changed
    or moved. ``received`` is when the update reached this process (monotonic seconds).
    """

    revision: int
    reset: bool = False
    library: str = ""
    agents: tuple[TaskView, ...] = ()
    deltas: tuple[SkillDelta, ...] = ()
    bounds: tuple[TaskBounds, ...] = ()
    barriers: tuple[Barrier, ...] | None = None
    markers: tuple[TaskMarker, ...] | None = None
    statuses: tuple[AgentStatus, ...] = ()
    changed_ids: frozenset[str] = frozenset()
    summary: str = ""
    received: float = field(default_factory=time.monotonic)
    state: MissionState | None = field(default=None, compare=False)
    event: MissionEvent | None = None

    @property
    def touched(self) -> tuple[str, ...]:
        """The robots whose task this update changed (every robot on a reset)."""
        if self.reset:
            return tuple(view.agent for view in self.agents)
        return tuple(bounds.agent for bounds in self.bounds)


def view_update(update: MirrorUpdate, state: MissionState | None) -> ViewUpdate:
    """Turn a mirror update into a :class:`ViewUpdate` (with the mirror's lock held)."""
    statuses = tuple(c.new for c in update.changes if isinstance(c, AgentStatusChanged))
    summary = update.event.summary if update.event is not None else ""
    if state is None:
        return ViewUpdate(update.revision, statuses=statuses)
    if any(isinstance(c, MissionReset) for c in update.changes):
        own = MissionState(state.content(), state.revision)
        return ViewUpdate(
            update.revision,
            reset=True,
            library=own.library,
            agents=tuple(TaskView.live(own, agent) for agent in own.agents),
            barriers=tuple(own.barriers),
            markers=tuple(own.markers),
            statuses=statuses,
            summary=summary,
            state=own,
        )
    deltas = tuple(c for c in update.changes if isinstance(c, SkillDelta))
    agents: list[str] = []
    changed: set[str] = set()
    for delta in deltas:
        _add_once(agents, delta_agent(delta))
        changed.update(delta_ids(delta))
    barriers = any(isinstance(c, (BarrierPut, BarrierRemoved)) for c in update.changes)
    markers = any(isinstance(c, (MarkerPut, MarkerRemoved)) for c in update.changes)
    return ViewUpdate(
        update.revision,
        deltas=deltas,
        bounds=tuple(TaskBounds.of(state, agent) for agent in agents if agent in state.agents),
        barriers=tuple(state.barriers) if barriers else None,
        markers=tuple(state.markers) if markers else None,
        statuses=statuses,
        changed_ids=frozenset(changed),
        summary=summary,
        event=update.event,
    )


def delta_agent(delta: SkillDelta) -> str:
    """The robot whose task ``delta`` changed."""
    if isinstance(delta, SkillsMoved):
        return delta.agent
    return delta.new.agent if isinstance(delta, SkillChanged) else delta.skill.agent


def delta_ids(delta: SkillDelta) -> tuple[str, ...]:
    """The skills ``delta`` added, changed, removed or moved."""
    if isinstance(delta, SkillsMoved):
        return tuple(move_columns(delta.moves)[0])
    return (delta.new.id,) if isinstance(delta, SkillChanged) else (delta.skill.id,)


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
