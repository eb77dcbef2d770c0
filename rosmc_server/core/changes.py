"""Changes and events: how the mission moves from one revision to the next.

Every accepted operation produces exactly one :class:`MissionEvent`. Its
:class:`Change` is a small patch (only what changed) that the state applies;
replaying the same events on the same start state rebuilds the mission
exactly, which is how the journal recovers after a crash.
"""

from __future__ import annotations

import enum
from dataclasses import dataclass
from typing import TYPE_CHECKING

from .model import Barrier, SkillInstance, TaskMarker

if TYPE_CHECKING:
    from .state import MissionContent


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
    order, then the blueprint order, then barrier and marker puts. A
    ``replacement`` replaces the whole content and must come alone.
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


@dataclass(frozen=True)
class MissionEvent:
    """One accepted change: the revision it produced, what it was, and the patch."""

    revision: int
    kind: EventKind
    agent: str
    summary: str
    stamp: float
    change: Change


@dataclass(frozen=True)
class Proposal:
    """A validated change an operation proposes, before it gets its revision."""

    kind: EventKind
    agent: str
    summary: str
    change: Change
