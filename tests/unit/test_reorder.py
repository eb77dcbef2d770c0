"""Whole-order reorders as moves, decoded in one pass, against the moves' plain definition.

The definition: moves apply one after the other, each taking its skill out and putting it
at its index (``play_one_by_one``). ``moves_between`` must give the fewest such moves;
``play_moves`` must give what they give, or None (never a wrong order) for moves no
canonical planner makes; the mission state, its deadlock check and the undo history,
which decode many moves at once, must agree with the definition too.
"""

from __future__ import annotations

import itertools
from collections.abc import Sequence
from typing import Any

import pytest
from hypothesis import given
from hypothesis import strategies as st

from rosmc_server.core import Change, MissionState, RuleViolation
from rosmc_server.core.model.changes import SkillMove, moves_between
from rosmc_server.core.model.moves import MoveList
from rosmc_server.core.model.reorder import play_moves, play_one_by_one
from rosmc_server.core.model.state import BULK_MOVES
from rosmc_server.core.rules.barriers import check_moves, check_new_barrier, find_deadlock
from rosmc_server.core.rules.undo import inverse_change
from tests.unit.test_change_indexes import (
    SETTINGS,
    Groups,
    assert_indexes_agree,
    assert_names_a_real_cycle,
    missions,
    scanned,
)


def longest_increasing_length(values: list[int]) -> int:
    """Quadratic and obviously right."""
    best = [1] * len(values)
    for i, j in itertools.combinations(range(len(values)), 2):
        if values[i] < values[j]:
            best[j] = max(best[j], best[i] + 1)
    return max(best, default=0)


@st.composite
def reorders(draw: Any) -> tuple[list[str], list[str], int]:
    """A stretch of ids, a new order of it (shuffled, or a few skills dragged), an offset."""
    current = [f"s{n}" for n in range(draw(st.integers(0, 60)))]
    if draw(st.booleans()):
        order = list(draw(st.permutations(current)))
    else:
        order = list(current)
        for _ in range(draw(st.integers(0, 4)) if current else 0):
            taken = order.pop(draw(st.integers(0, len(order) - 1)))
            order.insert(draw(st.integers(0, len(order))), taken)
    return current, order, draw(st.integers(0, 5))


@SETTINGS
@given(reorders())
def test_moves_between_gives_the_fewest_moves_and_play_moves_decodes_them(
    reorder: tuple[list[str], list[str], int],
) -> None:
    current, order, offset = reorder
    moves = moves_between(current, order, offset)
    assert play_one_by_one(current, moves, offset) == order
    position = {skill_id: n for n, skill_id in enumerate(order)}
    fewest = len(current) - longest_increasing_length([position[s] for s in current])
    assert len(moves) == fewest
    assert play_moves(current, moves, offset) == order


@SETTINGS
@given(st.integers(1, 30), st.data())
def test_play_moves_never_gives_a_wrong_order(length: int, data: Any) -> None:
    current = [f"s{n}" for n in range(length)]
    moves = data.draw(
        st.lists(
            st.builds(SkillMove, st.sampled_from(current), st.integers(2, length + 1)),
            min_size=1,
            max_size=25,
        )
    )
    decoded = play_moves(current, moves, 2)
    assert decoded is None or decoded == play_one_by_one(current, moves, 2)


def test_play_moves_refuses_moves_it_cannot_decode() -> None:
    current = ["a", "b", "c", "d"]
    # 'd' between 'b' and 'c': after no staying skill's run of moved ones.
    moves = [SkillMove("a", 3), SkillMove("d", 1)]
    assert play_one_by_one(current, moves) == ["b", "d", "c", "a"]
    assert play_moves(current, moves) in (None, ["b", "d", "c", "a"])
    assert play_moves(current, [SkillMove("a", 1), SkillMove("a", 2)]) is None  # twice
    assert play_moves(current, [SkillMove("x", 1)]) is None  # not in the stretch


def shuffled_keeping_members(ids: list[str], members: set[str], order: list[int]) -> list[str]:
    """``ids`` in the order of the permutation ``order``, barrier members kept in place."""
    shuffled = [ids[n] for n in order]
    places = [n for n, skill_id in enumerate(shuffled) if skill_id in members]
    kept = [skill_id for skill_id in ids if skill_id in members]
    for place, skill_id in zip(places, kept, strict=True):
        shuffled[place] = skill_id
    return shuffled


@SETTINGS
@given(missions(), st.data())
def test_many_moves_change_the_state_as_played_one_by_one(
    mission: tuple[MissionState, Groups], data: Any
) -> None:
    state, groups = mission
    tasks = scanned(state)
    agent = max(tasks, key=lambda a: len(tasks[a]))
    ids = tasks[agent]
    keep = data.draw(st.booleans())
    members = {s for g in groups for s in g} if keep else set()
    new = shuffled_keeping_members(ids, members, data.draw(st.permutations(range(len(ids)))))
    moves = moves_between(ids, new)
    after = {**tasks, agent: new}
    if find_deadlock(after, groups) is None:
        check_moves(state, agent, moves)
    else:
        with pytest.raises(RuleViolation, match="deadlock") as refused:
            check_moves(state, agent, moves)
        assert_names_a_real_cycle(refused.value, after, groups)
    inverse = inverse_change(state, Change(order_agent=agent, moves=moves))
    state.apply(Change(order_agent=agent, moves=moves))
    assert scanned(state) == after
    assert_indexes_agree(state, groups)
    if find_deadlock(after, groups) is None:  # a new barrier's check reads the moved members
        assert_new_barrier_checked_as_in_full(state, groups, data)
    state.apply(inverse)
    assert scanned(state) == tasks
    assert_indexes_agree(state, groups)


def assert_new_barrier_checked_as_in_full(state: MissionState, groups: Groups, data: Any) -> None:
    """A random new barrier is refused exactly when the check over whole tasks deadlocks."""
    tasks = scanned(state)
    members = {s for g in groups for s in g}
    free = {a: [s for s in ids if s not in members] for a, ids in tasks.items()}
    agents = [a for a in free if free[a]]
    if len(agents) < 2:
        return
    chosen = data.draw(st.lists(st.sampled_from(agents), min_size=2, max_size=4, unique=True))
    group = tuple(data.draw(st.sampled_from(free[a])) for a in chosen)
    if find_deadlock(tasks, [*groups, group]) is None:
        check_new_barrier(state, group)
    else:
        with pytest.raises(RuleViolation, match="deadlock") as refused:
            check_new_barrier(state, group)
        assert_names_a_real_cycle(refused.value, tasks, [*groups, group])


def test_a_whole_random_order_is_decoded_not_played_move_by_move() -> None:
    from tests.unit.test_change_indexes import state_of

    ids = [f"a{n}" for n in range(400)]
    state = state_of({"A": ids, "B": ["b0"]}, [])
    new = list(reversed(ids))
    moves = moves_between(ids, new)
    assert len(moves) >= BULK_MOVES
    assert state.order_after_moves("A", moves) == (0, new)
    state.apply(Change(order_agent="A", moves=moves))
    assert scanned(state)["A"] == new


def test_a_whole_new_order_is_planned_once_not_decoded_again(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    # The planner knows the new order: checking, undo history and apply all take it.
    import random

    from rosmc_server.core.model import task_order as state_module
    from rosmc_server.core.rules.editing import plan_reorder
    from tests.unit.test_change_indexes import state_of

    ids = [f"a{n}" for n in range(400)]
    state = state_of({"A": ids, "B": ["b0"]}, [])
    decoded: list[int] = []
    real = state_module.play_moves

    def counting(*args: Any) -> Any:
        decoded.append(len(args[1]))
        return real(*args)

    monkeypatch.setattr(state_module, "play_moves", counting)
    new = random.Random(3).sample(ids, len(ids))
    proposal = plan_reorder(state, "A", new)
    assert len(proposal.change.moves) >= BULK_MOVES
    assert state.members_after_moves("A", proposal.change.moves) == []
    state.apply(proposal.change)
    assert scanned(state)["A"] == new
    assert decoded == []


def test_the_collector_is_paused_for_a_reorder_and_restored_after() -> None:
    import gc

    from rosmc_server.core.collector import collector_paused

    assert gc.isenabled()
    with pytest.raises(RuntimeError), collector_paused():
        assert not gc.isenabled()
        raise RuntimeError("a refused reorder")
    assert gc.isenabled()
    gc.disable()
    try:
        with collector_paused():
            assert not gc.isenabled()
        assert not gc.isenabled()  # off before: off after
    finally:
        gc.enable()


@given(st.permutations(range(12)), st.integers(0, 11), st.integers(0, 11), st.sampled_from("dfm"))
def test_an_order_that_is_no_permutation_is_refused(
    order: list[int], at: int, other: int, fault: str
) -> None:
    current = [f"s{n}" for n in range(12)]
    new = [current[n] for n in order]
    moves_between(current, new, 3)  # a permutation: accepted
    if fault == "d":  # one id twice, another missing
        new[at] = new[other] if at != other else "ghost"
    elif fault == "f":  # an id from elsewhere
        new[at] = "ghost"
    else:  # one id short
        del new[at]
    with pytest.raises(ValueError):
        moves_between(current, new, 3)


@SETTINGS
@given(reorders())
def test_a_move_list_reads_as_the_moves_it_holds(reorder: tuple[list[str], list[str], int]) -> None:
    # The planner's two lists stand for SkillMove objects wherever moves are read.
    current, order, offset = reorder
    moves = moves_between(current, order, offset)
    ids, indexes = columns(moves)
    objects = tuple(
        SkillMove(skill_id, index) for skill_id, index in zip(ids, indexes, strict=True)
    )
    assert moves == objects and objects == moves and list(moves) == list(objects)
    assert len(moves) == len(objects) and hash(moves) == hash(moves_between(current, order, offset))
    assert all(moves[k] == objects[k] for k in range(len(objects)))
    assert moves[1:] == objects[1:] and play_one_by_one(current, moves, offset) == order
    assert moves != objects[:-1] or not objects
    if objects:
        assert moves != (*objects[:-1], SkillMove(objects[-1].skill_id, objects[-1].index + 1))


def columns(moves: Sequence[SkillMove]) -> tuple[Sequence[str], Sequence[int]]:
    assert isinstance(moves, MoveList)
    return moves.ids, moves.indexes


def test_a_move_list_needs_an_index_per_id() -> None:
    with pytest.raises(ValueError):
        MoveList(["a", "b"], [1])
