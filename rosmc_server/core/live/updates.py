"""Events applied to a mission, and what they changed as typed values.

:func:`apply_event` is the one way to move a mission from one revision to the next with an
event: the server's resume, the recording history, replay and every client's
:class:`~rosmc_server.core.live.mirror.MissionMirror` use it. :func:`apply_and_describe` also
says what changed (skill added / changed / removed, order, barrier, marker), so views can
update only what an event touched.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass

from ..errors import NotFound, RosmcError, RuleViolation
from ..model.changes import Change, EventKind, MissionEvent, SkillMove
from ..model.model import Barrier, SkillInstance, TaskMarker
from ..model.state import MissionState
from ..robots.agent_status import AgentStatus


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
    if _needs_snapshot(event):
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
    """Skills moved within an agent's task, one after the other (see :class:`SkillMove`).

    An old journal's reorder (the whole new order) is described by its moves too.
    """

    agent: str
    moves: Sequence[SkillMove]


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

    The changes come in the order :meth:`MissionState.apply` makes them (removals, skills
    put, a new order, barriers and markers put), each index as it is at that moment: a
    view that applies them one after the other ends equal to ``state``. Only what the
    event touches is looked at, so the cost is the change's, not the mission's.
    """
    if event.revision != state.revision + 1 or _needs_snapshot(event):
        apply_event(state, event)  # raises the error that says why
    change = event.change
    if change.replacement is not None:
        apply_event(state, event)
        return (MissionReset(state),)
    changes: list[MirrorChange] = []
    for barrier_id in change.removed_barrier_ids:
        barrier = _barrier_or_none(state, barrier_id)
        if barrier is not None:
            changes.append(BarrierRemoved(barrier))
            state.apply(Change(removed_barrier_ids=(barrier_id,)))
    for skill_id in change.removed_skill_ids:
        agent, index = state.locate(skill_id)
        changes.append(SkillRemoved(state.task(agent)[index], index))
        state.apply(Change(removed_skill_ids=(skill_id,)))
    for name in change.removed_marker_names:
        changes.append(MarkerRemoved(state.marker(name)))
        state.apply(Change(removed_marker_names=(name,)))
    for placed in change.put_skills:
        old = state.skill(placed.skill.id) if state.has_skill(placed.skill.id) else None
        state.apply(Change(put_skills=(placed,)))
        _, index = state.locate(placed.skill.id)
        if old is None:
            changes.append(SkillAdded(placed.skill, index))
        else:
            changes.append(SkillChanged(old, placed.skill, index))
    if change.order_agent:
        moves = change.moves or state.moves_for_order(change.order_agent, change.blueprint_order)
        state.apply(Change(order_agent=change.order_agent, moves=moves))
        changes.append(SkillsMoved(change.order_agent, moves))
    for barrier in change.put_barriers:
        changes.append(BarrierPut(_barrier_or_none(state, barrier.id), barrier))
        state.apply(Change(put_barriers=(barrier,)))
    for marker in change.put_markers:
        old_marker = state.marker(marker.name) if state.has_marker(marker.name) else None
        changes.append(MarkerPut(old_marker, marker))
        state.apply(Change(put_markers=(marker,)))
    state.revision = event.revision
    return tuple(changes)


def _needs_snapshot(event: MissionEvent) -> bool:
    return event.kind is EventKind.MISSION_REPLACED and event.change.replacement is None


def _barrier_or_none(state: MissionState, barrier_id: str) -> Barrier | None:
    try:
        return state.barrier(barrier_id)
    except NotFound:
        return None
