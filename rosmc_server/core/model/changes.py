"""Changes and events: how the mission moves from one revision to the next.

Every accepted operation produces exactly one :class:`MissionEvent`. Its
:class:`Change` is a small patch (only what changed) that the state applies;
replaying the same events on the same start state rebuilds the mission
exactly, which is how the journal recovers after a crash.
"""

from __future__ import annotations

import enum
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Protocol

from .content import MissionContent
from .model import Barrier, SkillInstance, TaskMarker
from .moves import MoveList as MoveList
from .moves import SkillMove as SkillMove
from .reorder import canonical_moves


class EventKind(enum.IntEnum):
    """What an event did (numbers match ``rosmc/MissionEvent``)."""

    SKILL_ADDED = 0
    SKILL_EDITED = 1
    SKILL_DELETED = 2
    SKILLS_REORDERED = 3
    SYNC_REQUESTED = 4
    SYNC_CONFIRMED = 5
    SYNC_DECLINED = 6
    UNSYNC_REQUESTED = 7
    UNSYNC_CONFIRMED = 8
    STATUS_CHANGED = 9
    SKILL_STOPPED = 10
    SKILL_RETRIED = 11
    SKILL_SKIPPED = 12
    BARRIER_ADDED = 13
    BARRIER_DELETED = 14
    MARKER_ADDED = 15
    MARKER_MOVED = 16
    MARKER_RENAMED = 17
    MARKER_DELETED = 18
    MISSION_REPLACED = 19
    UPLOAD_CANCELLED = 20


@dataclass(frozen=True)
class PlacedSkill:
    """A skill to insert at ``index`` of its agent's task, or to replace if its id exists."""

    index: int
    skill: SkillInstance


@dataclass(frozen=True)
class Change:
    """A patch to the mission state, applied in a fixed order.

    Order: removals (barriers, skills, markers), then skill puts in the given
    order, then ``order_agent``'s moves one after the other, then barrier and
    marker puts. A ``replacement`` replaces the whole content and must come alone.

    ``blueprint_order`` is how reorders were recorded before moves existed: the
    agent's whole editable blueprint in its new order. It is still read (old
    journals replay); new changes carry ``moves``, whose size is the reorder's.
    """

    put_skills: tuple[PlacedSkill, ...] = ()
    removed_skill_ids: tuple[str, ...] = ()
    order_agent: str = ""
    blueprint_order: tuple[str, ...] = ()
    put_barriers: tuple[Barrier, ...] = ()
    removed_barrier_ids: tuple[str, ...] = ()
    put_markers: tuple[TaskMarker, ...] = ()
    removed_marker_names: tuple[str, ...] = ()
    replacement: MissionContent | None = None
    moves: Sequence[SkillMove] = ()


@dataclass(frozen=True)
class MissionEvent:
    """One accepted change: the revision it produced, what it was, and the patch.

    ``undoes``: the revision of the edit this event takes back (an undo, or a redo that
    takes back an undo), 0 if it takes none back.
    """

    revision: int
    kind: EventKind
    agent: str
    summary: str
    stamp: float
    change: Change
    undoes: int = 0


@dataclass(frozen=True)
class Proposal:
    """A validated change an operation proposes, before it gets its revision."""

    kind: EventKind
    agent: str
    summary: str
    change: Change
    undoes: int = 0  # as MissionEvent.undoes


class ChangeObserver(Protocol):
    """Told each step of a :class:`Change` as the state makes it, with indexes as they
    are at that moment (:func:`~rosmc_server.core.live.updates.apply_event` describes
    an event so)."""

    def skill_removed(self, skill: SkillInstance, index: int) -> None:
        """``skill`` left its agent's task; it was at ``index``."""

    def skill_put(self, old: SkillInstance | None, new: SkillInstance, index: int) -> None:
        """``new`` was inserted (``old`` None) or replaced ``old``, at ``index``."""

    def skills_moved(self, agent: str, moves: Sequence[SkillMove]) -> None:
        """``agent``'s skills moved, one move after the other."""

    def barrier_removed(self, barrier: Barrier) -> None:
        """``barrier`` was deleted."""

    def barrier_put(self, old: Barrier | None, new: Barrier) -> None:
        """``new`` was added (``old`` None) or replaced ``old``."""

    def marker_removed(self, marker: TaskMarker) -> None:
        """``marker`` was deleted."""

    def marker_put(self, old: TaskMarker | None, new: TaskMarker) -> None:
        """``new`` was added (``old`` None) or replaced ``old``."""


def moves_between(current: Sequence[str], order: Sequence[str], offset: int = 0) -> MoveList:
    """The fewest moves that turn ``current`` into ``order`` (a permutation of it, else
    ValueError).

    Skills of a longest run already in the right relative order stay; each other
    skill, taken in its new order, moves to just after its new predecessor, so
    the moves apply one after the other. Indexes are ``offset`` plus the index in
    the sequence (``current`` is a task's tail starting at ``offset``). The cost is
    linear in the orders (see :mod:`.reorder`).
    """
    return MoveList(*canonical_moves(current, order, offset))
