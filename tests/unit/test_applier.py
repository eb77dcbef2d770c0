"""The one event applier (rosmc_server.core.live.updates.apply_event), kind by kind.

A real :class:`Mission` makes an event of every :class:`EventKind`. Applied one after the
other to a copy of the start, by :func:`apply_event`, they give the server's mission at
every revision; and the typed changes the applier returns, taken by a view that has no
rule of the core (:class:`DescribedView`), give it too, each change checked against what
the view held at that moment.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from rosmc_server.core import (
    EventKind,
    MarkerType,
    Mission,
    MissionContent,
    MissionEvent,
    MissionState,
    Pose,
    SkillStatus,
    TaskMarker,
    load_library,
)
from rosmc_server.core.live.updates import (
    MissionReset,
    SkillChanged,
    SkillRemoved,
    SkillsMoved,
    apply_event,
)
from rosmc_server.core.model.changes import Change, SkillMove
from tests.unit.conftest import make_mission
from tests.unit.described_view import DescribedView

REPO = Path(__file__).resolve().parents[2]
LIBRARY = load_library(REPO / "rosmc_server" / "config" / "mars_team.yaml")
S = SkillStatus
Step = tuple[MissionEvent, MissionContent]


def every_kind(mission: Mission) -> list[Step]:
    """Events of every kind from ``mission``, each with the mission's content after it."""
    steps: list[Step] = []

    def keep(event: MissionEvent) -> MissionEvent:
        steps.append((event, mission.state.content()))
        return event

    keep(mission.add_marker(TaskMarker("site", MarkerType.POSE, Pose(3, 4))))
    keep(mission.add_skill("drone", "take_off", {"altitude": 5.0}))
    keep(mission.load(mission.state.content(), "plan.yaml"))
    for skill, bindings in (("navigate_to", {"target": "site"}), ("land", {})):
        keep(mission.add_skill("drone", skill, bindings=bindings))
    keep(mission.add_skill("science_rover", "navigate_to", bindings={"target": "site"}))
    keep(mission.add_skill("science_rover", "explore"))
    keep(mission.add_skill("science_rover", "explore", index=0))
    drone = [s.id for s in mission.state.task("drone")]
    rover = [s.id for s in mission.state.task("science_rover")]
    keep(mission.reorder("drone", [drone[1], drone[0], drone[2]]))
    keep(mission.move_skills("drone", [SkillMove(drone[2], 0), SkillMove(drone[0], 2)]))
    keep(mission.edit_skill(drone[0], {"altitude": 9.0}, label="up"))
    keep(mission.add_barrier([drone[1], rover[1]]))
    keep(mission.delete_barrier(mission.state.barriers[-1].id))
    keep(mission.add_barrier([drone[1], rover[0]]))
    keep(mission.move_marker("site", Pose(5, 6)))  # the bound skills follow
    keep(mission.rename_marker("site", "crater"))
    keep(mission.undo())  # the rename taken back
    first = mission.state.task("drone")[0].id
    keep(mission.synchronize("drone", first))
    keep(mission.decline_synchronize("drone", [first], "the robot is busy"))
    keep(mission.synchronize("drone"))
    keep(mission.cancel_uploads("drone"))
    keep(mission.synchronize("drone"))
    sent = [s.id for s in mission.state.task("drone")]
    keep(mission.confirm_synchronized("drone", sent))
    keep(mission.unsynchronize("drone", sent[-1]))
    keep(mission.confirm_unsynchronized("drone", [sent[-1]]))
    keep(mission.report_status(sent[0], S.RUNNING))
    keep(mission.stop("drone"))
    keep(mission.report_status(sent[0], S.RUNNING))
    keep(mission.report_status(sent[0], S.FAILURE))
    retried = keep(mission.retry(sent[0])).change.put_skills[-1].skill.id
    keep(mission.report_status(retried, S.RUNNING))
    keep(mission.report_status(retried, S.FAILURE))
    keep(mission.skip(retried))
    keep(mission.delete_skills([rover[0], rover[2]]))
    keep(mission.add_marker(TaskMarker("", MarkerType.POSITION, Pose(1, 1))))
    keep(mission.delete_marker(mission.state.markers[-1].name))
    return steps


@pytest.fixture(scope="module")
def steps() -> tuple[MissionContent, list[Step]]:
    mission = make_mission(LIBRARY)
    return mission.state.content(), every_kind(mission)


def test_the_events_cover_every_kind(steps: tuple[MissionContent, list[Step]]) -> None:
    _, made = steps
    assert {event.kind for event, _ in made} == set(EventKind)


def test_events_and_their_descriptions_give_the_server_mission_at_every_revision(
    steps: tuple[MissionContent, list[Step]],
) -> None:
    start, made = steps
    state = MissionState(start, 0)
    view = DescribedView(state)
    for event, after in made:
        changes = apply_event(state, event)
        view.take(changes)
        assert state.revision == event.revision
        assert state.content() == after, event.kind
        assert view.matches(state), event.kind
        replaced = event.kind is EventKind.MISSION_REPLACED
        assert any(isinstance(c, MissionReset) for c in changes) == replaced


def test_a_description_holds_each_index_as_it_was_at_that_step() -> None:
    mission = make_mission(LIBRARY)
    for skill in ("take_off", "navigate_to", "land", "take_off"):
        mission.add_skill("drone", skill)
    ids = [s.id for s in mission.state.task("drone")]
    state = MissionState(mission.state.content(), mission.revision)
    changes = apply_event(state, mission.delete_skills([ids[1], ids[3], ids[0]]))
    removed = [(c.skill.id, c.index) for c in changes if isinstance(c, SkillRemoved)]
    assert removed == [(ids[1], 1), (ids[3], 2), (ids[0], 0)]
    assert [s.id for s in state.task("drone")] == [ids[2]]


def test_a_synchronize_describes_each_skill_changed_in_place() -> None:
    mission = make_mission(LIBRARY)
    for _ in range(5):
        mission.add_skill("science_rover", "explore")
    state = MissionState(mission.state.content(), mission.revision)
    changes = apply_event(state, mission.synchronize("science_rover"))
    assert [(type(c), c.index) for c in changes] == [(SkillChanged, i) for i in range(5)]
    assert all(isinstance(c, SkillChanged) and c.old.transfer != c.new.transfer for c in changes)


def test_an_old_journals_whole_order_is_described_by_its_moves() -> None:
    mission = make_mission(LIBRARY)
    for _ in range(6):
        mission.add_skill("drone", "take_off")
    ids = [s.id for s in mission.state.task("drone")]
    state = MissionState(mission.state.content(), mission.revision)
    view = DescribedView(state)
    order = ids[3:] + ids[:3]
    old = MissionEvent(
        state.revision + 1,
        EventKind.SKILLS_REORDERED,
        "drone",
        "drone's blueprint reordered",
        1.0,
        Change(order_agent="drone", blueprint_order=tuple(order)),
    )
    changes = apply_event(state, old)
    assert len(changes) == 1 and isinstance(changes[0], SkillsMoved) and changes[0].moves
    view.take(changes)
    assert [s.id for s in state.task("drone")] == order and view.matches(state)
