"""Events applied to a mission, and what they changed as typed values.

:func:`apply_event` is the one way to move a mission from one revision to the next with an
event: the server's resume, the recording history, replay and every client's
:class:`~rosmc_server.core.mirror.MissionMirror` use it. :func:`apply_and_describe` also
says what changed (skill added / changed / removed, order, barrier, marker), so views can
update only what an event touched.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

from .agent_status import AgentStatus
from .changes import EventKind, MissionEvent
from .errors import NotFound, RosmcError, RuleViolation
from .model import Barrier, SkillInstance, TaskMarker
from .state import MissionState


class SnapshotNeeded(RosmcError):
    """The event cannot be applied without a snapshot (it replaced the whole mission)."""


def apply_event(state: MissionState, event: MissionEvent) -> None:
    """Apply ``event`` to ``state``, which must be at the revision just before it.

    Raises:
        RuleViolation: the event does not follow the state's revision.
        SnapshotNeeded: the event replaced the mission and carries no content (as events
            on the wire do); the snapshot at ``event.revision`` is needed.
    """
    if event.revision != state.revision + 1:
        raise RuleViolation(
            f"event revision {event.revision} does not follow revision {state.revision}"
        )
    if event.kind is EventKind.MISSION_REPLACED and event.change.replacement is None:
        raise SnapshotNeeded(f"revision {event.revision} replaced the mission; fetch it")
    state.apply(event.change)
    state.revision = event.revision


# -- what listeners hear ---------------------------------------------------------------------
@dataclass(frozen=True)
class MissionReset:
    """The whole mission was (re)loaded from a snapshot: rebuild every view of it."""

    state: MissionState


@dataclass(frozen=True)
class SkillAdded:
    """A new skill at ``index`` of its agent's task."""

    skill: SkillInstance
    index: int


@dataclass(frozen=True)
class SkillChanged:
    """A skill changed in place (status, parameters, transfer, label, ...)."""

    old: SkillInstance
    new: SkillInstance
    index: int


@dataclass(frozen=True)
class SkillRemoved:
    """A skill left its agent's task (it was at ``index`` before)."""

    skill: SkillInstance
    index: int


@dataclass(frozen=True)
class SkillsMoved:
    """An agent's task has a new order: ``order`` is every skill id, in task order."""

    agent: str
    order: tuple[str, ...]


@dataclass(frozen=True)
class BarrierPut:
    """A barrier was added (``old`` None) or replaced."""

    old: Barrier | None
    new: Barrier


@dataclass(frozen=True)
class BarrierRemoved:
    """A barrier was deleted."""

    barrier: Barrier


@dataclass(frozen=True)
class MarkerPut:
    """A task marker was added (``old`` None), moved or renamed into ``new``."""

    old: TaskMarker | None
    new: TaskMarker


@dataclass(frozen=True)
class MarkerRemoved:
    """A task marker was deleted (or renamed away: a :class:`MarkerPut` follows)."""

    marker: TaskMarker


@dataclass(frozen=True)
class AgentStatusChanged:
    """A robot's live status changed (link, telemetry, current skill, policy)."""

    old: AgentStatus | None
    new: AgentStatus


MirrorChange = (
    MissionReset
    | SkillAdded
    | SkillChanged
    | SkillRemoved
    | SkillsMoved
    | BarrierPut
    | BarrierRemoved
    | MarkerPut
    | MarkerRemoved
    | AgentStatusChanged
)


@dataclass(frozen=True)
class MirrorUpdate:
    """What one snapshot, event or status message changed, and the revision after it.

    ``event`` is the mission event applied (None for a snapshot or agent statuses).
    """

    revision: int
    changes: tuple[MirrorChange, ...]
    event: MissionEvent | None = None


Listener = Callable[[MirrorUpdate], None]


def apply_and_describe(state: MissionState, event: MissionEvent) -> tuple[MirrorChange, ...]:
    """Apply ``event`` to ``state`` (as :func:`apply_event`) and say what it changed.

    Removals come first, then skills put (added or changed in place, with their index
    after the event), a new order, then barriers and markers put: the order in which
    :meth:`MissionState.apply` applies them.
    """
    change = event.change
    # Only what the event touches is looked up: the cost is the change's, not the mission's.
    touched_barriers = {*change.removed_barrier_ids, *(b.id for b in change.put_barriers)}
    old_barriers = {b: _barrier_or_none(state, b) for b in touched_barriers}
    touched_markers = {*change.removed_marker_names, *(m.name for m in change.put_markers)}
    old_markers = {m: state.marker(m) for m in touched_markers if state.has_marker(m)}
    removed: list[MirrorChange] = [
        BarrierRemoved(barrier)
        for barrier_id in change.removed_barrier_ids
        if (barrier := old_barriers[barrier_id]) is not None
    ]
    for skill_id in change.removed_skill_ids:
        agent, index = state.locate(skill_id)
        removed.append(SkillRemoved(state.task(agent)[index], index))
    removed += [MarkerRemoved(state.marker(name)) for name in change.removed_marker_names]
    removed_ids = set(change.removed_skill_ids)
    old_skills = {
        placed.skill.id: state.skill(placed.skill.id)
        for placed in change.put_skills
        if placed.skill.id not in removed_ids and state.has_skill(placed.skill.id)
    }
    apply_event(state, event)
    put: list[MirrorChange] = []
    for placed in change.put_skills:
        _, index = state.locate(placed.skill.id)
        old = old_skills.get(placed.skill.id)
        put.append(
            SkillAdded(placed.skill, index)
            if old is None
            else SkillChanged(old, placed.skill, index)
        )
    if change.order_agent:
        order = tuple(skill.id for skill in state.task(change.order_agent))
        put.append(SkillsMoved(change.order_agent, order))
    removed_barriers = set(change.removed_barrier_ids)
    put += [
        BarrierPut(None if b.id in removed_barriers else old_barriers.get(b.id), b)
        for b in change.put_barriers
    ]
    removed_markers = set(change.removed_marker_names)
    put += [
        MarkerPut(None if m.name in removed_markers else old_markers.get(m.name), m)
        for m in change.put_markers
    ]
    return (*removed, *put)


def _barrier_or_none(state: MissionState, barrier_id: str) -> Barrier | None:
    try:
        return state.barrier(barrier_id)
    except NotFound:
        return None
