"""The mission state's indexes and the incremental deadlock check, against full scans.

A skill's position key, each task's barrier members in order, the deadlock check that
follows barriers from the new or moved one only, and the moves a whole new order becomes:
each is compared with the plain computation over every skill (``find_deadlock`` over the
whole tasks, ``enumerate`` over a task) on random missions after random changes.
"""

from __future__ import annotations

import itertools
import re
from typing import Any

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from rosmc_server.core import (
    Barrier,
    Change,
    MissionContent,
    MissionState,
    PlacedSkill,
    RuleViolation,
    SkillInstance,
)
from rosmc_server.core.model.changes import SkillMove, moves_between
from rosmc_server.core.rules.barriers import check_moves, check_new_barrier, find_deadlock

Tasks = dict[str, list[str]]
Groups = list[tuple[str, ...]]
EDGE = re.compile(r"(\w+) runs '([^']+)' before '([^']+)'")


def skill(skill_id: str, agent: str) -> SkillInstance:
    return SkillInstance(id=skill_id, agent=agent, skill="noop", label=skill_id, params={})


def state_of(tasks: Tasks, groups: Groups) -> MissionState:
    content = MissionContent(
        "unit_team",
        {agent: [skill(s, agent) for s in ids] for agent, ids in tasks.items()},
        {f"b{n}": Barrier(f"b{n}", group) for n, group in enumerate(groups)},
    )
    return MissionState(content)


def scanned(state: MissionState) -> Tasks:
    return {agent: [s.id for s in state.task(agent)] for agent in state.agents}


def moved(tasks: Tasks, agent: str, moves: list[SkillMove]) -> Tasks:
    """``tasks`` with ``moves`` played on plain lists."""
    result = {a: list(ids) for a, ids in tasks.items()}
    for move in moves:
        result[agent].remove(move.skill_id)
        result[agent].insert(move.index, move.skill_id)
    return result


def assert_names_a_real_cycle(error: RuleViolation, tasks: Tasks, groups: Groups) -> None:
    """The refusal's cycle: each edge follows its task, and the edges chain via barriers."""
    edges = EDGE.findall(str(error))
    assert edges, str(error)
    point = {s: n for n, group in enumerate(groups) for s in group}
    for agent, before, after in edges:
        assert tasks[agent].index(before) < tasks[agent].index(after)
    for (_, _, after), (_, before, _) in itertools.pairwise([*edges, edges[0]]):
        assert point[after] == point[before]


@st.composite
def missions(draw: Any) -> tuple[MissionState, Groups]:
    """A mission whose barriers do not deadlock, then shaken by random changes.

    Inserting skills in a run at one place (past the keys' spacing), deleting skills
    and moving skills that are in no barrier change every index the check reads
    without changing the barriers' order.
    """
    agents = [f"r{n}" for n in range(draw(st.integers(2, 4)))]
    tasks = {a: [f"{a}s{i}" for i in range(draw(st.integers(0, 7)))] for a in agents}
    groups: Groups = []
    for _ in range(draw(st.integers(0, 6))):
        free = {a: [s for s in ids if all(s not in g for g in groups)] for a, ids in tasks.items()}
        candidates = [a for a in agents if free[a]]
        if len(candidates) < 2:
            break
        chosen = draw(st.lists(st.sampled_from(candidates), min_size=2, max_size=4, unique=True))
        group = tuple(draw(st.sampled_from(free[a])) for a in chosen)
        if find_deadlock(tasks, [*groups, group]) is None:
            groups.append(group)
    state = state_of(tasks, groups)
    members = {s for g in groups for s in g}
    fresh = itertools.count()
    for _ in range(draw(st.integers(0, 12))):
        agent = draw(st.sampled_from(agents))
        task = scanned(state)[agent]
        loose = [s for s in task if s not in members]
        what = draw(st.sampled_from(["insert", "insert", "run", "delete", "move"]))
        if what in ("insert", "run"):
            at = draw(st.integers(0, len(task)))
            for _ in range(40 if what == "run" else 1):  # 40 at one place: keys spread
                put = PlacedSkill(at, skill(f"{agent}x{next(fresh)}", agent))
                state.apply(Change(put_skills=(put,)))
        elif what == "delete" and loose:
            state.apply(Change(removed_skill_ids=(draw(st.sampled_from(loose)),)))
        elif what == "move" and loose:
            move = SkillMove(draw(st.sampled_from(loose)), draw(st.integers(0, len(task) - 1)))
            state.apply(Change(order_agent=agent, moves=(move,)))
    return state, groups


SETTINGS = settings(max_examples=300, deadline=None, suppress_health_check=[HealthCheck.too_slow])


def assert_indexes_agree(state: MissionState, groups: Groups) -> None:
    """Every skill's index and neighbouring barrier members are what a scan finds."""
    members = {s for g in groups for s in g}
    for agent, ids in scanned(state).items():
        in_barriers = [s for s in ids if s in members]
        for index, skill_id in enumerate(ids):
            assert state.locate(skill_id) == (agent, index)
            earlier = [s for s in in_barriers if ids.index(s) < index]
            later = [s for s in in_barriers if ids.index(s) > index]
            expected = (earlier[-1] if earlier else None, later[0] if later else None)
            assert state.members_around(skill_id) == expected


@SETTINGS
@given(missions())
def test_indexes_agree_with_a_scan(mission: tuple[MissionState, Groups]) -> None:
    assert_indexes_agree(*mission)


@SETTINGS
@given(missions(), st.data())
def test_a_new_barrier_is_refused_exactly_when_the_full_check_finds_a_deadlock(
    mission: tuple[MissionState, Groups], data: Any
) -> None:
    state, groups = mission
    tasks = scanned(state)
    members = {s for g in groups for s in g}
    free = {a: [s for s in ids if s not in members] for a, ids in tasks.items()}
    agents = [a for a in free if free[a]]
    if len(agents) < 2:
        return
    chosen = data.draw(st.lists(st.sampled_from(agents), min_size=2, max_size=4, unique=True))
    group = tuple(data.draw(st.sampled_from(free[a])) for a in chosen)
    full = find_deadlock(tasks, [*groups, group])
    if full is None:
        check_new_barrier(state, group)
    else:
        with pytest.raises(RuleViolation, match="deadlock") as refused:
            check_new_barrier(state, group)
        assert_names_a_real_cycle(refused.value, tasks, [*groups, group])
    assert scanned(state) == tasks, "the check changes nothing"


@SETTINGS
@given(missions(), st.data())
def test_moves_are_refused_exactly_when_the_full_check_finds_a_deadlock(
    mission: tuple[MissionState, Groups], data: Any
) -> None:
    state, groups = mission
    tasks = scanned(state)
    agent = data.draw(st.sampled_from([a for a in tasks if tasks[a]] or [""]))
    if not agent:
        return
    ids = tasks[agent]
    moves = data.draw(
        st.lists(
            st.builds(SkillMove, st.sampled_from(ids), st.integers(0, len(ids) - 1)),
            min_size=1,
            max_size=3,
        )
    )
    after = moved(tasks, agent, moves)
    if find_deadlock(after, groups) is None:
        check_moves(state, agent, moves)
    else:
        with pytest.raises(RuleViolation, match="deadlock") as refused:
            check_moves(state, agent, moves)
        assert_names_a_real_cycle(refused.value, after, groups)
    assert scanned(state) == tasks, "the check changes nothing"
    state.apply(Change(order_agent=agent, moves=tuple(moves)))
    assert scanned(state) == after
    assert_indexes_agree(state, groups)


def longest_increasing_length(values: list[int]) -> int:
    """Quadratic and obviously right."""
    best = [1] * len(values)
    for i, j in itertools.combinations(range(len(values)), 2):
        if values[i] < values[j]:
            best[j] = max(best[j], best[i] + 1)
    return max(best, default=0)


@settings(max_examples=500, deadline=None)
@given(st.integers(0, 12).flatmap(lambda n: st.permutations([f"s{i}" for i in range(n)])))
def test_a_new_order_becomes_the_fewest_moves(order: list[str]) -> None:
    current = sorted(order, key=lambda s: int(s[1:]))
    moves = moves_between(current, order, offset=3)
    assert moved({"a": ["x", "y", "z", *current]}, "a", list(moves))["a"][3:] == order
    rank = [int(s[1:]) for s in order]
    assert len(moves) == len(order) - longest_increasing_length(rank)


def test_a_long_task_keeps_its_indexes_through_many_insertions_at_one_place() -> None:
    state = state_of({"a": ["first", "last"], "b": ["b0", "b1", "b2"]}, [("last", "b1")])
    for n in range(200):  # each new skill goes right after "first": the keys run out often
        state.apply(Change(put_skills=(PlacedSkill(1, skill(f"new{n}", "a")),)))
    ids = scanned(state)["a"]
    assert ids == ["first", *(f"new{n}" for n in reversed(range(200))), "last"]
    assert [state.locate(s)[1] for s in ids] == list(range(len(ids)))
    assert state.members_around("new0") == (None, "last")
    with pytest.raises(RuleViolation, match="deadlock"):
        check_new_barrier(state, ["new5", "b2"])  # a: new5 before last; b: b1 before b2
    check_new_barrier(state, ["first", "b0"])
