"""Skill barriers: membership rules, started skills, and deadlock detection."""

from __future__ import annotations

from typing import Any

import pytest

from rosmc_server.core import (
    EventKind,
    InvalidRequest,
    NotFound,
    RuleViolation,
    SkillStatus,
    StaleRevision,
)
from rosmc_server.core.rules.barriers import describe_cycle, find_deadlock

S = SkillStatus


def test_add_and_delete_barrier(mission: Any, drv: Any, accepted: Any) -> None:
    a, b, c = drv.add("alpha"), drv.add("bravo"), drv.add("charlie")
    event = accepted(mission, EventKind.BARRIER_ADDED, mission.add_barrier, [a, b, c])
    barrier = event.change.put_barriers[0]
    assert barrier.skill_ids == (a, b, c)
    assert barrier.id.startswith("barrier-")
    assert all(mission.state.barrier_of(i) == barrier for i in (a, b, c))
    assert "alpha" in event.summary and a in event.summary
    event = accepted(mission, EventKind.BARRIER_DELETED, mission.delete_barrier, barrier.id)
    assert mission.state.barriers == ()
    assert mission.state.barrier_of(a) is None
    # Members are free to join a new barrier.
    mission.add_barrier([a, b])


def test_barrier_may_include_synchronized_skills(mission: Any, drv: Any) -> None:
    a, b = drv.add("alpha"), drv.add("bravo")
    drv.sync("alpha")
    barrier = mission.add_barrier([a, b]).change.put_barriers[0]
    mission.delete_barrier(barrier.id)


@pytest.mark.parametrize(
    ("members", "error", "fragment"),
    [
        ([], InvalidRequest, "at least two"),
        (["a1"], InvalidRequest, "at least two"),
        (["a1", "a1"], InvalidRequest, "twice"),
        (["a1", "a2"], RuleViolation, "distinct agents"),
        (["a1", "b1", "a2"], RuleViolation, "distinct agents"),
        (["a1", "ghost"], NotFound, "'ghost'"),
        (["a1", "b1"], RuleViolation, "already in barrier"),
        (["b1", "c1"], RuleViolation, "already in barrier"),
    ],
)
def test_add_barrier_refusals(
    mission: Any, drv: Any, rejected: Any, members: list[str], error: Any, fragment: str
) -> None:
    names = {
        "a1": drv.add("alpha"),
        "a2": drv.add("alpha"),
        "b1": drv.add("bravo"),
        "c1": drv.add("charlie"),
    }
    existing = mission.add_barrier([names["a2"], names["b1"]]).change.put_barriers[0]
    if fragment == "already in barrier":
        assert existing.id in str(
            rejected(mission, error, mission.add_barrier, [names.get(m, m) for m in members])
        )
        return
    mission.delete_barrier(existing.id)
    rejected(
        mission, error, mission.add_barrier, [names.get(m, m) for m in members], match=fragment
    )


@pytest.mark.parametrize("status", [S.SYNCWAITING, S.RUNNING, S.PAUSED, S.SUCCESS, S.FAILURE])
def test_started_skills_cannot_join(mission: Any, drv: Any, rejected: Any, status: Any) -> None:
    a, b = drv.add("alpha"), drv.add("bravo")
    drv.sync("alpha")
    for step in {
        S.SYNCWAITING: [S.SYNCWAITING],
        S.RUNNING: [S.RUNNING],
        S.PAUSED: [S.RUNNING, S.PAUSED],
        S.SUCCESS: [S.RUNNING, S.SUCCESS],
        S.FAILURE: [S.RUNNING, S.FAILURE],
    }[status]:
        mission.report_status(a, step)
    rejected(mission, RuleViolation, mission.add_barrier, [a, b], match=status.name)


def test_started_skills_cannot_leave(mission: Any, drv: Any, rejected: Any) -> None:
    a, b = drv.add("alpha"), drv.add("bravo")
    barrier = mission.add_barrier([a, b]).change.put_barriers[0]
    drv.sync("alpha")
    drv.sync("bravo")
    mission.report_status(a, S.SYNCWAITING)
    rejected(mission, RuleViolation, mission.delete_barrier, barrier.id, match="SYNCWAITING")
    mission.report_status(b, S.SYNCWAITING)
    mission.report_status(a, S.RUNNING)
    mission.report_status(b, S.RUNNING)
    mission.report_status(a, S.SUCCESS)
    rejected(mission, RuleViolation, mission.delete_barrier, barrier.id, match="SUCCESS")


def test_skills_in_transfer_cannot_join_or_leave(mission: Any, drv: Any, rejected: Any) -> None:
    a, b, c = drv.add("alpha"), drv.add("bravo"), drv.add("charlie")
    barrier = mission.add_barrier([a, b]).change.put_barriers[0]
    mission.synchronize("alpha")
    rejected(mission, RuleViolation, mission.add_barrier, [a, c], match="being uploaded")
    rejected(mission, RuleViolation, mission.delete_barrier, barrier.id, match="being uploaded")
    rejected(mission, RuleViolation, mission.delete_skills, [b], match="being uploaded")
    mission.confirm_synchronized("alpha", [a])
    mission.unsynchronize("alpha")
    rejected(mission, RuleViolation, mission.delete_barrier, barrier.id, match="removed")
    rejected(mission, RuleViolation, mission.delete_skills, [b], match="removed")
    mission.confirm_unsynchronized("alpha", [a])
    mission.delete_barrier(barrier.id)


def test_delete_barrier_refusals(mission: Any, rejected: Any, drv: Any) -> None:
    a, b = drv.add("alpha"), drv.add("bravo")
    barrier = mission.add_barrier([a, b]).change.put_barriers[0]
    rejected(mission, NotFound, mission.delete_barrier, "ghost", match="'ghost'")
    rejected(mission, NotFound, mission.delete_barrier, a)
    rejected(mission, StaleRevision, mission.delete_barrier, barrier.id, base_revision=0)
    rejected(mission, StaleRevision, mission.add_barrier, [a, b], base_revision=0)


def test_barrier_ids_never_collide_with_skill_ids(library: Any) -> None:
    from rosmc_server.core import Mission

    ids = iter(["same", "same", "same", "other", "same", "other", "fresh"])
    mission = Mission(library, new_id=lambda prefix: next(ids))
    mission.add_skill("alpha", "move")
    mission.add_skill("bravo", "move")
    barrier = mission.add_barrier(["same", "other"]).change.put_barriers[0]
    assert barrier.id == "fresh"


# -- deadlock ----------------------------------------------------------------------


def test_two_agent_deadlock_is_refused_with_the_cycle(
    mission: Any, drv: Any, rejected: Any
) -> None:
    x1, y1 = drv.adds("alpha", 2)
    y2, x2 = drv.adds("bravo", 2)
    mission.add_barrier([x1, x2])
    error = rejected(mission, RuleViolation, mission.add_barrier, [y1, y2], match="deadlock")
    message = str(error)
    assert f"alpha runs '{x1}' before '{y1}'" in message
    assert f"bravo runs '{y2}' before '{x2}'" in message


def test_three_agent_deadlock_is_refused(mission: Any, drv: Any, rejected: Any) -> None:
    a1, a2 = drv.adds("alpha", 2)
    b1, b2 = drv.adds("bravo", 2)
    c1, c2 = drv.adds("charlie", 2)
    mission.add_barrier([a2, b1])
    mission.add_barrier([b2, c1])
    error = rejected(mission, RuleViolation, mission.add_barrier, [c2, a1], match="deadlock")
    message = str(error)
    for agent, before, after in (("alpha", a1, a2), ("bravo", b1, b2), ("charlie", c1, c2)):
        assert f"{agent} runs '{before}' before '{after}'" in message


def test_deadlock_through_intermediate_skills(mission: Any, drv: Any, rejected: Any) -> None:
    x1, _, y1 = drv.adds("alpha", 3)
    y2, _, x2 = drv.adds("bravo", 3)
    mission.add_barrier([x1, x2])
    rejected(mission, RuleViolation, mission.add_barrier, [y1, y2], match="deadlock")


def test_consistent_barriers_are_accepted(mission: Any, drv: Any) -> None:
    x1, y1 = drv.adds("alpha", 2)
    x2, y2 = drv.adds("bravo", 2)
    x3, y3 = drv.adds("charlie", 2)
    mission.add_barrier([x1, x2, x3])
    mission.add_barrier([y1, y2, y3])
    mission.add_skill("alpha", "noop", index=1)
    assert len(mission.state.barriers) == 2


def test_find_deadlock_directly() -> None:
    tasks = {"A": ["x1", "y1"], "B": ["y2", "x2"], "C": ["z"]}
    assert find_deadlock(tasks, [("x1", "x2")]) is None
    cycle = find_deadlock(tasks, [("x1", "x2"), ("y1", "y2")])
    assert cycle is not None
    assert {(e.agent, e.before, e.after) for e in cycle} == {
        ("A", "x1", "y1"),
        ("B", "y2", "x2"),
    }
    assert describe_cycle(cycle).count("runs") == 2
    assert find_deadlock({}, []) is None
    assert find_deadlock({"A": ["a", "b", "c"]}, []) is None
    # A longer chain of barriers without a cycle.
    chain = {"A": ["a1", "a2"], "B": ["b1", "b2"], "C": ["c1", "c2"]}
    assert find_deadlock(chain, [("a2", "b1"), ("b2", "c1")]) is None
    assert find_deadlock(chain, [("a2", "b1"), ("b2", "c1"), ("c2", "a1")]) is not None
