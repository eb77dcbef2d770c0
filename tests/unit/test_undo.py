"""Undo and redo of blueprint, barrier and marker edits, and every way an undo is refused."""

from __future__ import annotations

import copy
import random
from typing import Any

from rosmc_server.core import (
    EventKind,
    InvalidRequest,
    MarkerType,
    Pose,
    RosmcError,
    RuleViolation,
    StaleRevision,
    TaskMarker,
)

SPOT = TaskMarker("spot", MarkerType.POSE, Pose(3.0, 4.0))


def test_undo_of_add_deletes_the_skill_and_redo_brings_it_back(
    mission: Any, drv: Any, accepted: Any, snap: Any
) -> None:
    first = drv.add("alpha")
    before = copy.deepcopy(snap(mission)["tasks"])
    added = mission.add_skill("alpha", "scan")
    skill_id = added.change.put_skills[0].skill.id
    undo = accepted(mission, EventKind.SKILL_DELETED, mission.undo, added.revision)
    assert drv.ids("alpha") == [first]
    assert snap(mission)["tasks"] == before
    assert undo.summary.startswith(f"undo of revision {added.revision} (")
    accepted(mission, EventKind.SKILL_ADDED, mission.undo, undo.revision)  # the redo
    assert drv.ids("alpha") == [first, skill_id]


def test_undo_of_edit_restores_every_field(mission: Any, drv: Any, accepted: Any) -> None:
    skill_id = drv.add("alpha", params={"speed": 1.5}, label="go")
    old = mission.state.skill(skill_id)
    edit = mission.edit_skill(skill_id, {"speed": 0.5}, label="slow", timeout=9.0)
    accepted(mission, EventKind.SKILL_EDITED, mission.undo, edit.revision)
    assert mission.state.skill(skill_id) == old


def test_undo_of_delete_restores_place_and_barrier(mission: Any, drv: Any, accepted: Any) -> None:
    a1, a2, a3 = drv.adds("alpha", 3)
    b, c = drv.add("bravo"), drv.add("charlie")
    barrier = mission.add_barrier([a2, b, c]).change.put_barriers[0]
    deleted = mission.delete_skills([a2, c])
    assert mission.state.barriers == ()  # dissolved below two members
    accepted(mission, EventKind.SKILL_ADDED, mission.undo, deleted.revision)
    assert drv.ids("alpha") == [a1, a2, a3]
    assert drv.ids("charlie") == [c]
    assert mission.state.barrier(barrier.id) == barrier


def test_undo_of_reorder_restores_the_order(mission: Any, drv: Any, accepted: Any) -> None:
    ids = drv.adds("alpha", 5)
    moved = mission.reorder("alpha", [ids[3], ids[0], ids[4], ids[2], ids[1]])
    accepted(mission, EventKind.SKILLS_REORDERED, mission.undo, moved.revision)
    assert drv.ids("alpha") == ids


def test_undo_of_a_large_reorder_restores_the_order_and_redo_gives_it_again(
    mission: Any, drv: Any, accepted: Any
) -> None:
    # Enough moves that the undo history keeps the stretch, not the moves back.
    first = drv.add("alpha")
    ids = drv.adds("alpha", 40)
    new = ids[::2][::-1] + ids[1::2]
    moved = mission.reorder("alpha", [first, *new])  # the stretch starts after ``first``
    assert len(moved.change.moves) >= 16
    undo = accepted(mission, EventKind.SKILLS_REORDERED, mission.undo, moved.revision)
    assert drv.ids("alpha") == [first, *ids]
    accepted(mission, EventKind.SKILLS_REORDERED, mission.undo, undo.revision)  # the redo
    assert drv.ids("alpha") == [first, *new]


def test_undo_of_a_large_reorder_is_refused_once_a_skill_moved_or_was_sent(
    mission: Any, drv: Any, rejected: Any
) -> None:
    ids = drv.adds("alpha", 40)
    moved = mission.reorder("alpha", ids[::-1])
    mission.reorder("alpha", [ids[0], *ids[:0:-1]])
    rejected(mission, RuleViolation, mission.undo, moved.revision, match="was moved since")
    again = mission.reorder("alpha", ids)  # the stretch starts at ids[1]: ids[0] stays
    mission.synchronize("alpha", ids[1])
    rejected(mission, RuleViolation, mission.undo, again.revision, match="has been sent")


def test_undo_of_barrier_add_and_delete(mission: Any, drv: Any, accepted: Any) -> None:
    a, b = drv.add("alpha"), drv.add("bravo")
    added = mission.add_barrier([a, b])
    undo = accepted(mission, EventKind.BARRIER_DELETED, mission.undo, added.revision)
    assert mission.state.barriers == ()
    accepted(mission, EventKind.BARRIER_ADDED, mission.undo, undo.revision)
    assert mission.state.barrier_of(a) is not None


def test_undo_of_marker_move_moves_bound_skills_back(mission: Any, drv: Any, accepted: Any) -> None:
    mission.add_marker(SPOT)
    skill_id = drv.add("alpha", bindings={"target": "spot"})
    moved = mission.move_marker("spot", Pose(9.0, 9.0))
    assert mission.state.skill(skill_id).params["target"] == Pose(9.0, 9.0)
    accepted(mission, EventKind.MARKER_MOVED, mission.undo, moved.revision)
    assert mission.state.marker("spot") == SPOT
    assert mission.state.skill(skill_id).params["target"] == Pose(3.0, 4.0)


def test_undo_of_marker_rename_and_delete(mission: Any, drv: Any, accepted: Any) -> None:
    added = mission.add_marker(SPOT)
    skill_id = drv.add("alpha", bindings={"target": "spot"})
    renamed = mission.rename_marker("spot", "rock")
    accepted(mission, EventKind.MARKER_RENAMED, mission.undo, renamed.revision)
    assert mission.state.skill(skill_id).bindings == {"target": "spot"}
    mission.delete_skills([skill_id])
    deleted = mission.delete_marker("spot")
    accepted(mission, EventKind.MARKER_ADDED, mission.undo, deleted.revision)
    assert mission.state.marker("spot") == SPOT
    assert added.revision < deleted.revision


def test_undo_refused_once_the_skill_was_sent(mission: Any, drv: Any, rejected: Any) -> None:
    skill_id = drv.add("alpha")
    edit = mission.edit_skill(skill_id, {"speed": 0.5})
    drv.sync("alpha")
    rejected(mission, RuleViolation, mission.undo, edit.revision, match="has been sent to alpha")


def test_undo_refused_when_a_barrier_partner_was_sent(
    mission: Any, drv: Any, rejected: Any
) -> None:
    a, b = drv.add("alpha"), drv.add("bravo")
    mission.add_barrier([a, b])
    deleted = mission.delete_skills([a])  # the barrier dissolves
    drv.sync("bravo")
    rejected(mission, RuleViolation, mission.undo, deleted.revision, match="cannot come back")


def test_undo_refused_when_changed_since(mission: Any, drv: Any, rejected: Any) -> None:
    skill_id = drv.add("alpha")
    first = mission.edit_skill(skill_id, {"speed": 0.5})
    mission.edit_skill(skill_id, {"speed": 0.7})
    rejected(mission, RuleViolation, mission.undo, first.revision, match="was changed since")


def test_undo_refused_when_marker_gained_a_skill(mission: Any, drv: Any, rejected: Any) -> None:
    moved_to = Pose(1.0, 1.0)
    mission.add_marker(SPOT)
    moved = mission.move_marker("spot", moved_to)
    drv.add("alpha", bindings={"target": "spot"})
    rejected(mission, RuleViolation, mission.undo, moved.revision, match="was bound to")


def test_undo_refused_for_skill_that_joined_a_barrier(
    mission: Any, drv: Any, rejected: Any
) -> None:
    added = mission.add_skill("alpha", "move")
    mission.add_barrier([added.change.put_skills[0].skill.id, drv.add("bravo")])
    rejected(mission, RuleViolation, mission.undo, added.revision, match="joined barrier")


def test_undo_refused_for_what_is_not_an_edit(mission: Any, drv: Any, rejected: Any) -> None:
    drv.add("alpha")
    sync = mission.synchronize("alpha")
    rejected(mission, InvalidRequest, mission.undo, sync.revision, match="cannot be undone")
    rejected(mission, InvalidRequest, mission.undo, 999, match="cannot be undone")


def test_undo_refused_with_stale_base_revision(mission: Any, drv: Any, rejected: Any) -> None:
    added = mission.add_skill("alpha", "move")
    drv.add("bravo")
    rejected(mission, StaleRevision, mission.undo, added.revision, base_revision=added.revision)


def test_latest_walks_back_through_the_edits(mission: Any, drv: Any, rejected: Any) -> None:
    first, second = drv.add("alpha"), drv.add("alpha")
    assert drv.ids("alpha") == [first, second]
    mission.undo()
    assert drv.ids("alpha") == [first]
    undo = mission.undo()
    assert drv.ids("alpha") == []
    mission.undo(undo.revision)  # redo of the first add
    assert drv.ids("alpha") == [first]
    mission.undo()
    assert drv.ids("alpha") == []
    rejected(mission, InvalidRequest, mission.undo, match="no blueprint, barrier or marker edit")


def test_journal_replay_keeps_undo(mission: Any, drv: Any, new_mission_factory: Any) -> None:
    events = [mission.add_skill("alpha", "move"), mission.add_skill("alpha", "scan")]
    events.append(mission.undo())
    copy_of = new_mission_factory()
    for event in events:
        copy_of.replay(event)
    first_id = events[0].change.put_skills[0].skill.id
    assert copy_of.undo().change.removed_skill_ids == (first_id,)
    assert list(copy_of.state.task("alpha")) == []


def test_undoing_every_edit_in_turn_walks_back_through_each_state(
    mission: Any, drv: Any, snap: Any
) -> None:
    rng = random.Random(7)
    states = []
    for _ in range(60):
        before = _plan(snap(mission))
        try:
            _random_edit(mission, rng)
        except RosmcError:
            continue  # refused: nothing changed, nothing to undo
        states.append(before)
    assert len(states) > 30
    for before in reversed(states):
        mission.undo()
        assert _plan(snap(mission)) == before
    assert mission.history.latest() == 0


def _plan(data: dict[str, Any]) -> dict[str, Any]:
    return {key: value for key, value in data.items() if key != "revision"}


def _random_edit(mission: Any, rng: random.Random) -> None:
    agents = ["alpha", "bravo", "charlie"]
    agent = rng.choice(agents)
    ids = [s.id for s in mission.state.task(agent)]
    choice = rng.randrange(7)
    if choice <= 1 or not ids:
        index = rng.randrange(len(ids) + 1)
        mission.add_skill(agent, rng.choice(["move", "scan", "wait"]), index=index)
    elif choice == 2:
        mission.delete_skills(rng.sample(ids, rng.randint(1, min(2, len(ids)))))
    elif choice == 3:
        mission.reorder(agent, rng.sample(ids, len(ids)))
    elif choice == 4:
        mission.edit_skill(rng.choice(ids), label=f"step {rng.randrange(100)}")
    elif choice == 5:
        other = rng.choice([a for a in agents if a != agent])
        partners = [s.id for s in mission.state.task(other)]
        mission.add_barrier([rng.choice(ids), rng.choice(partners or ["none"])])
    else:
        barriers = mission.state.barriers
        if barriers:
            mission.delete_barrier(rng.choice(barriers).id)
        else:
            mission.add_marker(TaskMarker("", MarkerType.POSITION, Pose(rng.random(), 1.0)))
