"""Changes and events: how the mission moves from one revision to the next.

Every accepted operation produces exactly one :class:`MissionEvent`. Its
:class:`Change` is a small patch (only what changed) that the state applies;
replaying the same events on the same start state rebuilds the mission
exactly, which is how the journal recovers after a crash.
"""

from __future__ import annotations

import bisect
import enum
from collections.abc import Sequence
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
class SkillMove:
    """Move a skill within its agent's task: ``index`` is its index once moved."""

    skill_id: str
    index: int


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
    moves: tuple[SkillMove, ...] = ()


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


def moves_between(
    current: Sequence[str], order: Sequence[str], offset: int = 0
) -> tuple[SkillMove, ...]:
    """The fewest moves that turn ``current`` into ``order`` (a permutation of it).

    Skills of a longest run already in the right relative order stay; each other
    skill, taken in its new order, moves to just after its new predecessor, so
    the moves apply one after the other. Indexes are ``offset`` plus the index in
    the sequence (``current`` is a task's tail starting at ``offset``).
    """
    # Skills that keep their place at either end take no part (a drag and drop moves a
    # few skills: this leaves only the stretch between where they were and now are).
    pairs = zip(current, order, strict=True)
    head = next((i for i, (was, now) in enumerate(pairs) if was != now), len(order))
    tail = len(order)
    while tail > head and current[tail - 1] == order[tail - 1]:
        tail -= 1
    current, order, offset = current[head:tail], order[head:tail], offset + head
    position = {skill_id: index for index, skill_id in enumerate(order)}
    targets = [position[skill_id] for skill_id in current]
    staying = _longest_increasing(targets)
    # Where each skill sits, as a number: first where it is now, (i + 1) * scale for
    # index i; once moved, just after its new predecessor (a run of moved skills after
    # the same staying skill counts up from that skill's number, below the next one).
    scale = len(current) + 1
    place_now = [0] * len(order)
    for index, target in enumerate(targets):
        place_now[target] = (index + 1) * scale
    left: list[int] = []  # the places moved skills left, sorted
    taken: list[int] = []  # the places they moved to, sorted
    moves = []
    anchor, run = 0, 0
    for index, skill_id in enumerate(order):
        if index in staying:
            anchor, run = place_now[index], 0
            continue
        run += 1
        place = anchor + run
        bisect.insort(left, place_now[index])
        below = (place - 1) // scale - bisect.bisect_left(left, place)
        below += bisect.bisect_left(taken, place)
        bisect.insort(taken, place)
        moves.append(SkillMove(skill_id, offset + below))
    return tuple(moves)


def _longest_increasing(values: Sequence[int]) -> set[int]:
    """The values of a longest increasing run (subsequence) of ``values``."""
    tails: list[int] = []  # the smallest last value of an increasing run of each length
    ends: list[int] = []  # where in ``values`` that run ends
    previous: list[int] = []
    for index, value in enumerate(values):
        length = bisect.bisect_left(tails, value)
        if length == len(tails):
            tails.append(value)
            ends.append(index)
        else:
            tails[length] = value
            ends[length] = index
        previous.append(ends[length - 1] if length else -1)
    run: set[int] = set()
    index = ends[-1] if ends else -1
    while index >= 0:
        run.add(values[index])
        index = previous[index]
    return run
