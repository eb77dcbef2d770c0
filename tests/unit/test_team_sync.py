"""Synchronizing several robots in one change (core): all or nothing, one event, one upload each."""

from __future__ import annotations

from collections.abc import Callable

import pytest

from rosmc_server.core import Mission, NotFound, RuleViolation, Transfer
from rosmc_server.core.model.changes import EventKind
from rosmc_server.core.model.state import MissionState
from rosmc_server.core.robots.commands import CommandKind, commands_for_event

Uploads = dict[str, str | None]


def barrier_plan(mission: Mission) -> tuple[list[str], list[str], str]:
    """alpha and bravo with two skills each; a barrier between their second skills."""
    alpha = [mission.add_skill("alpha", "wait", {}).change.put_skills[0].skill.id for _ in "ab"]
    bravo = [mission.add_skill("bravo", "wait", {}).change.put_skills[0].skill.id for _ in "ab"]
    barrier = mission.add_barrier([alpha[1], bravo[1]]).change.put_barriers[0].id
    return alpha, bravo, barrier


def transfers(state: MissionState) -> dict[str, list[Transfer]]:
    """Every agent's skills' transfer states."""
    return {agent: [s.transfer for s in state.task(agent)] for agent in state.agents}


def test_every_robot_in_one_event_and_one_upload_per_robot(mission: Mission) -> None:
    alpha, bravo, barrier = barrier_plan(mission)
    revision = mission.revision
    event = mission.synchronize_team()  # every robot with planned skills, whole tasks
    assert (event.revision, event.kind, event.agent) == (revision + 1, EventKind.SYNC_REQUESTED, "")
    assert [p.skill.id for p in event.change.put_skills] == alpha + bravo
    assert transfers(mission.state)["charlie"] == []
    commands = commands_for_event(event, mission.state)
    assert [(c.agent, c.kind) for c in commands] == [
        ("alpha", CommandKind.UPLOAD),
        ("bravo", CommandKind.UPLOAD),
    ]
    assert [[s.id for s in c.skills] for c in commands] == [alpha, bravo]
    assert [[b.id for b in c.barriers] for c in commands] == [[barrier], [barrier]]


def test_each_robot_up_to_its_own_skill(mission: Mission) -> None:
    alpha, bravo, _ = barrier_plan(mission)
    event = mission.synchronize_team({"alpha": alpha[0], "bravo": None})
    assert [p.skill.id for p in event.change.put_skills] == [alpha[0], *bravo]
    assert transfers(mission.state)["alpha"] == [Transfer.UPLOADING, Transfer.NONE]


@pytest.mark.parametrize(
    ("uploads", "error"),
    [
        (lambda a, b: {"alpha": None, "bravo": a[0]}, RuleViolation),  # alpha's skill for bravo
        (lambda a, b: {"alpha": None, "charlie": None}, RuleViolation),  # nothing planned
        (lambda a, b: {"alpha": None, "bravo": "nosuch"}, NotFound),
        (lambda a, b: {}, RuleViolation),
    ],
)
def test_one_refusal_changes_nothing_for_anyone(
    mission: Mission, uploads: Callable[[list[str], list[str]], Uploads], error: type[Exception]
) -> None:
    alpha, bravo, _ = barrier_plan(mission)
    revision, before = mission.revision, transfers(mission.state)
    with pytest.raises(error):
        mission.synchronize_team(uploads(alpha, bravo))
    assert (mission.revision, transfers(mission.state)) == (revision, before)
