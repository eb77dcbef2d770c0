"""Skill barriers: adding and removing them, and refusing any that would deadlock.

A barrier makes its members start together, so it merges them into one point
in time. Each task orders its skills. A set of barriers deadlocks exactly when
the graph of "runs before" edges between these points has a cycle, e.g.
A:[x1, y1], B:[y2, x2] with barriers {x1, x2} and {y1, y2}.
"""

from __future__ import annotations

from collections.abc import Iterable, Iterator, Sequence
from dataclasses import dataclass

from ..errors import InvalidRequest, RuleViolation
from ..model.changes import Change, EventKind, Proposal, SkillMove
from ..model.model import Barrier, SkillInstance, SkillStatus
from ..model.moves import move_columns
from ..model.state import MissionState
from .deadlock import OrderEdge as OrderEdge  # callers import the deadlock search from here
from .deadlock import describe_cycle as describe_cycle
from .deadlock import find_deadlock as find_deadlock
from .legality import member_refusal, staying_refusal


def check_no_deadlock(
    state: MissionState,
    extra_group: Sequence[str] = (),
    order: tuple[str, Sequence[str]] | None = None,
) -> None:
    """Raise RuleViolation if the barriers (plus ``extra_group``) would deadlock.

    ``order`` replaces one agent's editable blueprint order, to check a reorder.
    The barriers in ``state`` never deadlock, so only cycles through what is new
    are looked for (see :func:`check_new_barrier` and :func:`check_moves`).
    """
    if extra_group:
        check_new_barrier(state, extra_group)
    if order is not None:
        check_moves(state, order[0], state.moves_for_order(order[0], order[1]))


def check_new_barrier(state: MissionState, skill_ids: Sequence[str]) -> None:
    """Raise RuleViolation if a barrier over ``skill_ids`` (existing non-members) deadlocks.

    Any new cycle passes through the new barrier. From a skill reached on one task, the
    earliest skill reached on another task through one barrier is a binary search away
    (see :mod:`..model.pair_index`), and an earlier skill reached on a task leads everywhere a
    later one does: the search keeps the earliest per agent and stops when one comes
    before the new barrier's member on its task. Its cost is a few binary searches per
    pair of agents, whatever the mission's size and however dense its barriers.
    """
    first = {state.agent_of(skill_id): skill_id for skill_id in skill_ids}
    reached = {agent: _Step(s, state.order_key(s)) for agent, s in first.items()}
    target = {agent: step.key for agent, step in reached.items()}
    work = list(reached)
    while work:
        agent = work.pop()
        step = reached[agent]
        for other in list(state.partner_agents(agent)):
            after = state.first_shared_after(step.skill_id, other)
            if after is None:
                continue
            barrier = state.barrier_of(after)
            assert barrier is not None, f"member {after} without a barrier"
            partner = next(m for m in barrier.skill_ids if state.agent_of(m) == other)
            key = state.order_key(partner)
            edge = OrderEdge(agent, step.skill_id, after)
            if other in target and key < target[other]:
                back = OrderEdge(other, partner, first[other])
                _refuse_cycle([*step.path(), edge, back])
            known = reached.get(other)
            if known is None or key < known.key:
                reached[other] = _Step(partner, key, step, edge)
                work.append(other)


@dataclass(frozen=True)
class _Step:
    """A skill the search reached, and how: the step before it and the edge from there."""

    skill_id: str
    key: int
    parent: _Step | None = None
    edge: OrderEdge | None = None

    def path(self) -> list[OrderEdge]:
        """The edges from the start to this step."""
        edges, step = [], self
        while step.parent is not None and step.edge is not None:
            edges.append(step.edge)
            step = step.parent
        return edges[::-1]


def check_moves(state: MissionState, agent: str, moves: Sequence[SkillMove]) -> None:
    """Raise RuleViolation if moving skills within ``agent``'s task makes the barriers deadlock.

    Moving a skill that is in no barrier never changes the barriers' order; a moved
    member's barrier is on any new cycle, so the search starts from those only.
    """
    ids = move_columns(moves)[0]
    members = state.members_of(agent)
    # A whole new order moves thousands of skills and a few members: look at those.
    moved = set(members).intersection(ids) if len(members) < len(ids) else set(ids)
    starts = {b.id for b in map(state.barrier_of, moved) if b is not None}
    if not starts:
        return
    graph = _BarrierGraph(state)
    after = state.members_after_moves(agent, moves)
    graph.next_member.update(zip(after, [*after[1:], None], strict=True))
    for start in sorted(starts):
        _refuse_cycle(graph.cycle_through(start))


class _BarrierGraph:
    """The barriers of a state as a graph, with one task's members reordered.

    A node is a barrier; an edge goes from a member to the next member on the
    same task. ``next_member`` holds what the reorder makes different; everything
    else is read from the state's indexes.
    """

    def __init__(self, state: MissionState) -> None:
        self.state = state
        self.next_member: dict[str, str | None] = {}

    def edges_from(self, barrier_id: str) -> Iterator[tuple[str, OrderEdge]]:
        """(next barrier, the task-order edge to it) for each member of ``barrier_id``."""
        for skill_id in self.state.barrier(barrier_id).skill_ids:
            if skill_id in self.next_member:
                after = self.next_member[skill_id]
            else:
                after = self.state.members_around(skill_id)[1]
            if after is None:
                continue
            barrier = self.state.barrier_of(after)
            assert barrier is not None, f"member {after} without a barrier"
            yield barrier.id, OrderEdge(self.state.agent_of(skill_id), skill_id, after)

    def cycle_through(self, start: str) -> list[OrderEdge] | None:
        """The edges of a cycle from ``start`` back to it, or None (depth-first search)."""
        came_by: dict[str, tuple[str, OrderEdge]] = {}
        stack = [start]
        seen = {start}
        while stack:
            node = stack.pop()
            for target, edge in self.edges_from(node):
                if target == start:
                    path = [edge]
                    while node != start:
                        node, back = came_by[node]
                        path.append(back)
                    return path[::-1]
                if target not in seen:
                    seen.add(target)
                    came_by[target] = (node, edge)
                    stack.append(target)
        return None


def _refuse_cycle(cycle: list[OrderEdge] | None) -> None:
    if cycle is not None:
        raise RuleViolation(
            "the barriers would deadlock, because each waits for another: " + describe_cycle(cycle)
        )


def plan_add_barrier(state: MissionState, skill_ids: Sequence[str], barrier_id: str) -> Proposal:
    """Barrier over ``skill_ids``: at least two skills on distinct agents, none started."""
    if len(skill_ids) < 2:
        raise InvalidRequest("a barrier needs at least two skills")
    if len(set(skill_ids)) != len(skill_ids):
        raise InvalidRequest("a barrier lists the same skill twice")
    members = [state.skill(skill_id) for skill_id in skill_ids]
    seen_agents: dict[str, str] = {}
    for skill in members:
        if skill.agent in seen_agents:
            raise RuleViolation(
                f"skills '{seen_agents[skill.agent]}' and '{skill.id}' are both on "
                f"{skill.agent}; barrier members must be on distinct agents"
            )
        seen_agents[skill.agent] = skill.id
        _check_member_changeable(state, skill, "join a barrier")
        existing = state.barrier_of(skill.id)
        if existing is not None:
            raise RuleViolation(f"skill '{skill.id}' is already in barrier '{existing.id}'")
    check_new_barrier(state, skill_ids)
    barrier = Barrier(barrier_id, tuple(skill_ids))
    agents = ", ".join(skill.agent for skill in members)
    return Proposal(
        EventKind.BARRIER_ADDED,
        "",
        f"barrier '{barrier_id}' makes {agents} start {', '.join(skill_ids)} together",
        Change(put_barriers=(barrier,)),
    )


def plan_delete_barrier(state: MissionState, barrier_id: str) -> Proposal:
    """Remove a barrier none of whose members has started."""
    barrier = state.barrier(barrier_id)
    for skill_id in barrier.skill_ids:
        _check_member_changeable(state, state.skill(skill_id), "leave its barrier")
    return Proposal(
        EventKind.BARRIER_DELETED,
        "",
        f"barrier '{barrier_id}' removed",
        Change(removed_barrier_ids=(barrier_id,)),
    )


def _check_member_changeable(state: MissionState, skill: SkillInstance, action: str) -> None:
    refusal = member_refusal(skill, action)
    if refusal is not None:
        raise RuleViolation(refusal)


def barrier_without(state: MissionState, removed: set[str]) -> Change:
    """Barrier updates for deleting skills ``removed``: shrink, or drop below two members.

    Raises RuleViolation if a member that stays has started or awaits a transfer,
    as for deleting the barrier itself.
    """
    put: list[Barrier] = []
    dropped: list[str] = []
    for barrier in state.barriers:
        if not removed.intersection(barrier.skill_ids):
            continue
        remaining = tuple(s for s in barrier.skill_ids if s not in removed)
        refusal = staying_refusal(state.skill(skill_id) for skill_id in remaining)
        if refusal is not None:
            raise RuleViolation(refusal)
        if len(remaining) >= 2:
            put.append(Barrier(barrier.id, remaining))
        else:
            dropped.append(barrier.id)
    return Change(put_barriers=tuple(put), removed_barrier_ids=tuple(dropped))


# -- a failed member's retry or skip ---------------------------------------------------------
def has_released(state: MissionState, barrier: Barrier) -> bool:
    """Whether the barrier's members have started together, as far as the ground can tell.

    A member reported RUNNING or SUCCESS has run, and a barrier member runs only once its
    barrier released. A paused, stopped or failed member may or may not have run, so it
    does not count: a robot that saw the release runs a rejoining member at once anyway.
    """
    return any(
        state.skill(skill_id).status in (SkillStatus.RUNNING, SkillStatus.SUCCESS)
        for skill_id in barrier.skill_ids
    )


def after_retry(state: MissionState, failed_id: str, fresh_id: str) -> tuple[Change, str]:
    """The barrier patch for retrying ``failed_id`` as ``fresh_id``, and what to say of it.

    Before the release the fresh instance takes the failed one's place, so the partners
    wait for the new attempt. After it the barrier stays the log of who started together
    and the new attempt runs alone.
    """
    barrier = state.barrier_of(failed_id)
    if barrier is None:
        return Change(), ""
    if has_released(state, barrier):
        return Change(), (
            f"its barrier '{barrier.id}' had released (the members started together), "
            "so the new attempt runs alone"
        )
    members = tuple(fresh_id if s == failed_id else s for s in barrier.skill_ids)
    partners = _agents(state, (s for s in members if s != fresh_id))
    return Change(put_barriers=(Barrier(barrier.id, members),)), (
        f"barrier '{barrier.id}' now waits for '{fresh_id}' (its partners on {partners} wait "
        "for the new attempt)"
    )


def after_skip(state: MissionState, failed_id: str) -> tuple[Change, str]:
    """The barrier patch for skipping ``failed_id``, and what to say of it.

    Before the release the partners would otherwise wait for ever: the skipped member
    leaves the barrier, and a barrier left with one member is dissolved.
    """
    barrier = state.barrier_of(failed_id)
    if barrier is None or has_released(state, barrier):
        return Change(), ""
    remaining = tuple(s for s in barrier.skill_ids if s != failed_id)
    partners = _agents(state, remaining)
    if len(remaining) >= 2:
        return Change(put_barriers=(Barrier(barrier.id, remaining),)), (
            f"it leaves barrier '{barrier.id}', whose other members ({partners}) still start "
            "together"
        )
    return Change(removed_barrier_ids=(barrier.id,)), (
        f"barrier '{barrier.id}' is dissolved, so {partners} goes on alone"
    )


def _agents(state: MissionState, skill_ids: Iterable[str]) -> str:
    return ", ".join(state.skill(skill_id).agent for skill_id in skill_ids)
