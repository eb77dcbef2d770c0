"""The one way an event moves a mission to the next revision, and what it changed.

:func:`apply_event` applies a :class:`MissionEvent` to a :class:`MissionState` and says
what changed as typed values (skill added / changed / removed, moves, barrier, marker).
Everything that moves a mission by an event uses it: the server's
:class:`~rosmc_server.core.rules.mission.Mission` (its own changes and a resume's journaled
ones), the recording history, replay, and every client's
:class:`~rosmc_server.core.live.mirror.MissionMirror`, whose listeners (the command GUI,
the rviz scene) update from the description instead of applying anything again.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass

from ..errors import RosmcError, RuleViolation
from ..model.changes import EventKind, MissionEvent, SkillMove
from ..model.model import Barrier, SkillInstance, TaskMarker
from ..model.state import MissionState
from ..robots.agent_status import AgentStatus


class SnapshotNeeded(RosmcError):
    """The event cannot be applied without a snapshot (it replaced the whole mission)."""


def apply_event(
    state: MissionState, event: MissionEvent, *, describe: bool = True
) -> tuple[MirrorChange, ...]:
    """Apply ``event`` to ``state``, which must be at the revision just before it, and say
    what it changed.

    The changes come in the order the state makes them (removals, skills put, moves,
    barriers and markers put), each index as it is at that moment: a view that applies
    them one after the other ends equal to ``state``. A replacement is one
    :class:`MissionReset`. The cost is the change's, not the mission's. ``describe``
    False: the same application, nothing described (the server and the history readers,
    which have no view to update, save a value per skill of a synchronize of thousands).

    Raises:
        RuleViolation: the event does not follow the state's revision.
        SnapshotNeeded: the event replaced the mission and carries no content (as events
            on the wire do); the snapshot at ``event.revision`` is needed.
    """
    if event.revision != state.revision + 1:
        raise RuleViolation(
            f"event revision {event.revision} does not follow revision {state.revision}"
        )
    if needs_snapshot(event):
        raise SnapshotNeeded(f"revision {event.revision} replaced the mission; fetch it")
    if event.change.replacement is not None:
        state.apply(event.change)
        state.revision = event.revision
        return (MissionReset(state),)
    described = _Described() if describe else None
    state.apply(event.change, described)
    state.revision = event.revision
    return () if described is None else tuple(described.changes)


def needs_snapshot(event: MissionEvent) -> bool:
    """Whether ``event`` replaced the mission without carrying it (as on the wire): only a
    snapshot can follow it."""
    return event.kind is EventKind.MISSION_REPLACED and event.change.replacement is None


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


class _Described:
    """Collects what :meth:`MissionState.apply` reports, as :data:`MirrorChange` values."""

    def __init__(self) -> None:
        self.changes: list[MirrorChange] = []

    def skill_removed(self, skill: SkillInstance, index: int) -> None:
        self.changes.append(SkillRemoved(skill, index))

    def skill_put(self, old: SkillInstance | None, new: SkillInstance, index: int) -> None:
        self.changes.append(
            SkillAdded(new, index) if old is None else SkillChanged(old, new, index)
        )

    def skills_moved(self, agent: str, moves: Sequence[SkillMove]) -> None:
        self.changes.append(SkillsMoved(agent, moves))

    def barrier_removed(self, barrier: Barrier) -> None:
        self.changes.append(BarrierRemoved(barrier))

    def barrier_put(self, old: Barrier | None, new: Barrier) -> None:
        self.changes.append(BarrierPut(old, new))

    def marker_removed(self, marker: TaskMarker) -> None:
        self.changes.append(MarkerRemoved(marker))

    def marker_put(self, old: TaskMarker | None, new: TaskMarker) -> None:
        self.changes.append(MarkerPut(old, new))
