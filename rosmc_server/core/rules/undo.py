"""Undo: an operator's blueprint edit taken back as a new change.

When an edit is committed, :class:`UndoHistory` keeps its inverse (worked out
from the state just before it) and what the edit left behind. Undoing the edit
later proposes the inverse as an ordinary change with a new revision, so the
journal records it like any other; it is refused, in one sentence, when one of
the skills it touches has since been sent to a robot or someone changed what
the edit produced. An undo is itself undoable: undoing it is the redo.
"""

from __future__ import annotations

import collections
from collections.abc import Sequence
from dataclasses import dataclass, field, replace

from ..errors import InvalidRequest, NotFound, RuleViolation
from ..model.changes import (
    Change,
    EventKind,
    MissionEvent,
    PlacedSkill,
    Proposal,
    SkillMove,
    moves_between,
)
from ..model.model import Barrier, SkillInstance, TaskMarker, skill_id_of
from ..model.state import BULK_MOVES, MissionState
from .barriers import check_moves, find_deadlock

# The event kind of an edit's inverse (an edit of either kind can be undone).
_INVERSE_KIND = {
    EventKind.SKILL_ADDED: EventKind.SKILL_DELETED,
    EventKind.SKILL_DELETED: EventKind.SKILL_ADDED,
    EventKind.SKILL_EDITED: EventKind.SKILL_EDITED,
    EventKind.SKILLS_REORDERED: EventKind.SKILLS_REORDERED,
    EventKind.BARRIER_ADDED: EventKind.BARRIER_DELETED,
    EventKind.BARRIER_DELETED: EventKind.BARRIER_ADDED,
    EventKind.MARKER_ADDED: EventKind.MARKER_DELETED,
    EventKind.MARKER_DELETED: EventKind.MARKER_ADDED,
    EventKind.MARKER_MOVED: EventKind.MARKER_MOVED,
    EventKind.MARKER_RENAMED: EventKind.MARKER_RENAMED,
}

UNDO_DEPTH = 200
"""How many of the latest edits can be undone (older ones are forgotten)."""


@dataclass(frozen=True)
class Left:
    """What an edit left in the mission: each touched item's value (None: absent)."""

    skills: dict[str, SkillInstance | None] = field(default_factory=dict)
    positions: dict[str, int] = field(default_factory=dict)
    stretch: Stretch | None = None
    barriers: dict[str, Barrier | None] = field(default_factory=dict)
    markers: dict[str, TaskMarker | None] = field(default_factory=dict)


@dataclass(frozen=True)
class Stretch:
    """A stretch of a task a large reorder gave a new order: its start, ids before and after.

    Its moves back are worked out only if the reorder is undone (they cost the stretch).
    """

    agent: str
    start: int
    before: tuple[str, ...]
    after: tuple[str, ...] = ()


@dataclass(frozen=True)
class UndoEntry:
    """An edit that can be undone: its revision, kind, summary and inverse."""

    revision: int
    kind: EventKind
    agent: str
    summary: str
    inverse: Change
    left: Left
    undoes: int = 0
    is_undo: bool = False


class UndoHistory:
    """The latest operator edits of a mission, each with the change that takes it back."""

    def __init__(self, depth: int = UNDO_DEPTH) -> None:
        self._entries: collections.OrderedDict[int, UndoEntry] = collections.OrderedDict()
        self._depth = depth
        self._undone: set[int] = set()
        self._stretch: Stretch | None = None  # of the reorder between inverse() and keep()

    def inverse(self, state: MissionState, kind: EventKind, change: Change) -> Change | None:
        """The change that takes ``change`` back, from the ``state`` just before it.

        None when the kind cannot be undone; a whole new mission forgets every edit.
        """
        if change.replacement is not None:
            self._entries.clear()
            self._undone.clear()
            return None
        if kind not in _INVERSE_KIND or (change.blueprint_order and not change.moves):
            return None  # not an edit (or a reorder journaled as a whole order, before moves)
        self._stretch = None
        if len(change.moves) >= BULK_MOVES and _is_reorder(change):
            played = state.order_after_moves(change.order_agent, change.moves)
            if played is not None:
                start, after = played
                task = state.task(change.order_agent)[start : start + len(after)]
                before = tuple(map(skill_id_of, task))
                self._stretch = Stretch(change.order_agent, start, before, tuple(after))
                return Change(order_agent=change.order_agent)
        return inverse_change(state, change)

    def keep(self, state: MissionState, event: MissionEvent, inverse: Change | None) -> None:
        """Remember a committed edit and its inverse (``state`` is just after it)."""
        if inverse is None:
            return
        if self._stretch is not None:
            left = replace(_left_by(state, Change()), stretch=self._stretch)
            self._stretch = None
        else:
            left = _left_by(state, event.change)
        undone = self._entries.get(event.undoes)
        if undone is not None:
            self._undone.add(event.undoes)
        is_undo = undone is not None and not undone.is_undo
        self._entries[event.revision] = UndoEntry(
            event.revision,
            event.kind,
            event.agent,
            event.summary,
            inverse,
            left,
            event.undoes,
            is_undo,
        )
        while len(self._entries) > self._depth:
            self._undone.discard(self._entries.popitem(last=False)[0])

    def latest(self) -> int:
        """The newest edit (or redo) not undone yet, or 0 if there is none.

        Undoing the latest again and again walks back through the edits.
        """
        for revision, entry in reversed(self._entries.items()):
            if not entry.is_undo and revision not in self._undone:
                return revision
        return 0

    def plan_undo(self, state: MissionState, revision: int) -> Proposal:
        """The proposal that undoes the edit made at ``revision``.

        Raises:
            InvalidRequest: no edit at that revision can be undone.
            RuleViolation: the edit's skills were sent since, or someone changed them.
        """
        if revision <= 0:
            raise InvalidRequest("there is no blueprint, barrier or marker edit left to undo")
        entry = self._entries.get(revision)
        if entry is None:
            raise InvalidRequest(
                f"revision {revision} is not one of the last {self._depth} blueprint, "
                "barrier or marker edits, so it cannot be undone"
            )
        _check_unchanged(state, entry)
        for skill_id in entry.inverse.removed_skill_ids:
            barrier = state.barrier_of(skill_id)
            if barrier is not None:
                raise RuleViolation(
                    f"skill '{skill_id}' joined barrier '{barrier.id}' since revision "
                    f"{revision}; remove the barrier first"
                )
        for barrier in entry.inverse.put_barriers:  # a barrier back: its members must be too
            for member in barrier.skill_ids:
                if state.has_skill(member) and not state.skill(member).is_editable:
                    raise RuleViolation(
                        f"skill '{member}' of barrier '{barrier.id}' has been sent since "
                        f"revision {revision}, so the barrier cannot come back"
                    )
        inverse = _placed_in_blueprint(state, entry.inverse)
        stretch = entry.left.stretch
        if stretch is not None:
            moves = moves_between(stretch.after, stretch.before, stretch.start)
            inverse = replace(inverse, moves=moves)
        _check_no_deadlock(state, inverse)
        return Proposal(
            _INVERSE_KIND[entry.kind],
            entry.agent,
            f"undo of revision {revision} ({entry.summary})",
            inverse,
            undoes=revision,
        )


def inverse_change(before: MissionState, change: Change) -> Change:
    """The change that turns the state after ``change`` back into ``before``'s."""
    added = tuple(p.skill.id for p in change.put_skills if not before.has_skill(p.skill.id))
    restored = [
        PlacedSkill(before.locate(p.skill.id)[1], before.skill(p.skill.id))
        for p in change.put_skills
        if before.has_skill(p.skill.id)
    ]
    removed = sorted((before.locate(i)[1], i) for i in change.removed_skill_ids)
    restored += [PlacedSkill(index, before.skill(skill_id)) for index, skill_id in removed]
    return Change(
        put_skills=tuple(restored),
        removed_skill_ids=added,
        order_agent=change.order_agent,
        moves=_inverse_moves(before, change.order_agent, change.moves),
        put_barriers=tuple(
            before.barrier(barrier_id)
            for barrier_id in _touched_barriers(change)
            if before.has_barrier(barrier_id)
        ),
        removed_barrier_ids=tuple(
            b.id for b in change.put_barriers if not before.has_barrier(b.id)
        ),
        put_markers=tuple(
            before.marker(name) for name in _touched_markers(change) if before.has_marker(name)
        ),
        removed_marker_names=tuple(
            m.name for m in change.put_markers if not before.has_marker(m.name)
        ),
    )


def _inverse_moves(
    before: MissionState, agent: str, moves: Sequence[SkillMove]
) -> Sequence[SkillMove]:
    """Moves that undo ``moves`` (applied one after the other), last one first.

    A few moves: only the moved skills' indexes are followed, so the cost is the moves',
    not the task's. Many: the stretch they reorder is decoded once and the moves back
    are those between the two orders (linear in the stretch).
    """
    if not agent or not moves:
        return ()
    played = before.order_after_moves(agent, moves) if len(moves) >= BULK_MOVES else None
    if played is not None:
        start, after = played
        before_ids = [skill.id for skill in before.task(agent)[start : start + len(after)]]
        return moves_between(after, before_ids, start)
    where = {move.skill_id: before.locate(move.skill_id)[1] for move in moves}
    back = []
    for move in moves:
        was, now = where[move.skill_id], move.index
        back.append(SkillMove(move.skill_id, was))
        for skill_id, index in where.items():  # the skills between shift by one
            if was < index <= now:
                where[skill_id] = index - 1
            elif now <= index < was:
                where[skill_id] = index + 1
        where[move.skill_id] = now
    return tuple(reversed(back))


def _touched_barriers(change: Change) -> list[str]:
    ids = list(change.removed_barrier_ids)
    return ids + [b.id for b in change.put_barriers if b.id not in ids]


def _touched_markers(change: Change) -> list[str]:
    names = list(change.removed_marker_names)
    return names + [m.name for m in change.put_markers if m.name not in names]


def _left_by(after: MissionState, change: Change) -> Left:
    """The value of everything ``change`` touched, in the state just after it."""
    skill_ids = [p.skill.id for p in change.put_skills] + list(change.removed_skill_ids)
    left = Left(
        skills={i: after.skill(i) if after.has_skill(i) else None for i in skill_ids},
        positions={m.skill_id: after.locate(m.skill_id)[1] for m in change.moves},
        barriers={
            i: after.barrier(i) if after.has_barrier(i) else None for i in _touched_barriers(change)
        },
        markers={
            n: after.marker(n) if after.has_marker(n) else None for n in _touched_markers(change)
        },
    )
    return left


def _check_unchanged(state: MissionState, entry: UndoEntry) -> None:
    """Refuse (one sentence) unless everything the edit touched is as it left it."""
    since = f"since revision {entry.revision}"
    for skill_id, value in entry.left.skills.items():
        now = state.skill(skill_id) if state.has_skill(skill_id) else None
        if now is not None and value is not None and not now.is_editable:
            raise RuleViolation(
                f"skill '{skill_id}' has been sent to {now.agent} {since}, "
                "so that edit can no longer be undone"
            )
        if now != value:
            raise RuleViolation(f"skill '{skill_id}' was changed {since}; undo that change first")
    if entry.left.stretch is not None:
        _check_stretch_unchanged(state, entry.left.stretch, since)
    for skill_id, index in entry.left.positions.items():
        skill = state.skill(skill_id)
        if not skill.is_editable:
            raise RuleViolation(
                f"skill '{skill_id}' has been sent to {skill.agent} {since}, "
                "so that reorder can no longer be undone"
            )
        if state.locate(skill_id)[1] != index:
            raise RuleViolation(f"skill '{skill_id}' was moved {since}; undo that move first")
    for barrier_id, barrier in entry.left.barriers.items():
        now_barrier = state.barrier(barrier_id) if state.has_barrier(barrier_id) else None
        if now_barrier != barrier:
            raise RuleViolation(f"barrier '{barrier_id}' was changed {since}")
        for member in barrier.skill_ids if barrier else ():
            if not state.skill(member).is_editable:
                raise RuleViolation(
                    f"skill '{member}' of barrier '{barrier_id}' has been sent {since}, "
                    "so the barrier can no longer be changed by an undo"
                )
    for name, marker in entry.left.markers.items():
        now_marker = state.marker(name) if state.has_marker(name) else None
        if now_marker != marker:
            raise RuleViolation(f"task marker '{name}' was changed {since}")
        bound = {s.id for s in state.bound_to(name) if not s.status.is_final} if marker else set()
        if bound - set(entry.left.skills):
            newly = sorted(bound - set(entry.left.skills))[0]
            raise RuleViolation(f"skill '{newly}' was bound to task marker '{name}' {since}")


def _check_stretch_unchanged(state: MissionState, stretch: Stretch, since: str) -> None:
    """Refuse unless the reordered stretch is as the reorder left it, still in the blueprint."""
    task = state.task(stretch.agent)[stretch.start : stretch.start + len(stretch.after)]
    now = tuple(skill.id for skill in task)
    if now != stretch.after:
        moved = next((a for a, b in zip(stretch.after, now, strict=False) if a != b), None)
        moved = moved or stretch.after[-1]
        raise RuleViolation(f"skill '{moved}' was moved {since}; undo that move first")
    if task and not task[0].is_editable:  # a synchronized skill: every one before it is too
        raise RuleViolation(
            f"skill '{task[0].id}' has been sent to {task[0].agent} {since}, "
            "so that reorder can no longer be undone"
        )


def _is_reorder(change: Change) -> bool:
    """Whether ``change`` only moves skills of one agent."""
    return change == Change(order_agent=change.order_agent, moves=change.moves)


def _placed_in_blueprint(state: MissionState, inverse: Change) -> Change:
    """``inverse`` with each skill it puts back inside its agent's editable blueprint.

    A deleted skill returns where it was; if robots took skills since (so the
    blueprint starts later), it returns at the blueprint's start instead.
    """
    placed = []
    for put in inverse.put_skills:
        if state.has_skill(put.skill.id):
            placed.append(put)
            continue
        start = state.sections(put.skill.agent).editable_start
        placed.append(replace(put, index=max(put.index, start)))
    return replace(inverse, put_skills=tuple(placed))


def _check_no_deadlock(state: MissionState, inverse: Change) -> None:
    """Refuse an undo whose restored order or barriers would deadlock with today's barriers."""
    if inverse.moves and not inverse.put_barriers:
        check_moves(state, inverse.order_agent, inverse.moves)
        return
    if not inverse.put_barriers:
        return
    # Rare (an undo that brings a barrier back): check the whole result on a scratch copy.
    scratch = MissionState(state.content(), state.revision)
    try:
        scratch.apply(inverse)
    except (KeyError, NotFound) as error:
        raise RuleViolation(f"the undo no longer fits the mission ({error})") from error
    tasks = {agent: [s.id for s in scratch.task(agent)] for agent in scratch.agents}
    if find_deadlock(tasks, [b.skill_ids for b in scratch.barriers]) is not None:
        raise RuleViolation(
            "the undo would bring back a barrier that now deadlocks with the others"
        )
