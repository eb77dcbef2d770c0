"""Whole missions: new and load, revisions and events, stale requests, replay."""

from __future__ import annotations

import copy
from typing import Any

import pytest

from rosmc_server.core import (
    EventKind,
    MarkerType,
    Mission,
    MissionContent,
    Pose,
    RuleViolation,
    SkillStatus,
    StaleRevision,
    TaskMarker,
    Transfer,
    random_ids,
)

S = SkillStatus


def test_a_new_mission_is_empty(mission: Any, library: Any) -> None:
    assert mission.revision == 0
    assert mission.state.agents == ("alpha", "bravo", "charlie")
    assert all(mission.state.task(agent) == [] for agent in mission.state.agents)
    assert mission.state.library == library.name
    assert mission.state.barriers == () and mission.state.markers == ()


def test_random_ids() -> None:
    first, second = random_ids("alpha"), random_ids("alpha")
    assert first.startswith("alpha-") and first != second


# -- new mission -----------------------------------------------------------------


def test_new_mission(mission: Any, drv: Any, accepted: Any) -> None:
    a, b = drv.add("alpha"), drv.add("bravo")
    mission.add_barrier([a, b])
    mission.add_marker(TaskMarker("rock", MarkerType.POSE, Pose(1.0)))
    drv.sync("alpha")
    drv.finish(a)
    event = accepted(mission, EventKind.MISSION_REPLACED, mission.new_mission)
    assert event.agent == "" and "new mission" in event.summary
    assert all(mission.state.task(agent) == [] for agent in mission.state.agents)
    assert mission.state.barriers == ()
    assert [m.name for m in mission.state.markers] == ["rock"]
    accepted(mission, EventKind.MISSION_REPLACED, mission.new_mission, keep_markers=False)
    assert mission.state.markers == ()
    # Ids of the old mission are free again; the id factory keeps counting anyway.
    assert drv.add("alpha") not in (a, b)


@pytest.mark.parametrize(
    "situation", ["synchronized", "running", "paused", "waiting", "uploading", "removing"]
)
def test_new_mission_and_load_refused_while_robots_hold_skills(
    mission: Any, drv: Any, rejected: Any, situation: str
) -> None:
    skill = drv.add("alpha")
    if situation == "uploading":
        mission.synchronize("alpha")
    else:
        drv.sync("alpha")
        steps = {
            "synchronized": [],
            "running": [S.RUNNING],
            "paused": [S.RUNNING, S.PAUSED],
            "waiting": [S.SYNCWAITING],
            "removing": [],
        }[situation]
        for step in steps:
            mission.report_status(skill, step)
        if situation == "removing":
            mission.unsynchronize("alpha")
    rejected(mission, RuleViolation, mission.new_mission, match=skill)
    content = MissionContent.empty(mission.library)
    rejected(mission, RuleViolation, mission.load, content, "file.yaml", match="unfinished")


def test_new_mission_allowed_with_only_finished_skills(mission: Any, drv: Any) -> None:
    done, failed = drv.adds("alpha", 2)
    drv.sync("alpha")
    drv.finish(done)
    drv.finish(failed, S.FAILURE)  # an unresolved failure holds nothing on the robot
    mission.new_mission()


def test_new_mission_on_stale_revision(mission: Any, drv: Any, rejected: Any) -> None:
    drv.add("alpha")
    rejected(mission, StaleRevision, mission.new_mission, base_revision=0)


# -- load ------------------------------------------------------------------------


def test_load_returns_unfinished_synchronized_skills_to_the_blueprint(
    mission: Any, drv: Any, accepted: Any, new_mission_factory: Any
) -> None:
    # Build the content to load in another mission, as a file would hold it.
    other = new_mission_factory()
    source = type(drv)(other)
    done, failed, running, waiting, uploading, blueprint = source.adds("alpha", 6)
    source.sync("alpha", waiting)
    source.finish(done)
    source.finish(failed, S.FAILURE)
    other.skip(failed)
    source.run(running)
    other.report_status(running, S.RUNNING, text="half way")
    other.synchronize("alpha", uploading)
    bravo = source.add("bravo")
    other.add_barrier([blueprint, bravo])
    other.add_marker(TaskMarker("rock", MarkerType.POSITION, Pose(2.0)))
    content = other.state.content()
    loaded_before = copy.deepcopy(content)

    drv.add("charlie")
    event = accepted(mission, EventKind.MISSION_REPLACED, mission.load, content, "saved.yaml")
    assert "saved.yaml" in event.summary
    task = {s.id: s for s in mission.state.task("alpha")}
    assert [s.id for s in mission.state.task("alpha")] == [
        done,
        failed,
        running,
        waiting,
        uploading,
        blueprint,
    ]
    assert task[done] == content.tasks["alpha"][0]
    assert task[failed] == content.tasks["alpha"][1]
    for skill_id in (running, waiting, uploading, blueprint):
        skill = task[skill_id]
        assert (skill.status, skill.transfer) == (S.IDLE, Transfer.NONE)
        assert (skill.status_text, skill.started) == ("", 0.0)
    assert mission.state.task("charlie") == []
    assert mission.state.barrier_of(blueprint) is not None
    assert mission.state.marker("rock").pose == Pose(2.0)
    # The given content object itself is not modified or aliased.
    assert content == loaded_before
    mission.edit_skill(running, label="again")
    assert content == loaded_before
    assert mission.state.sections("alpha").synced_end == 2


def test_load_on_stale_revision(mission: Any, drv: Any, rejected: Any) -> None:
    drv.add("alpha")
    content = MissionContent.empty(mission.library)
    rejected(mission, StaleRevision, mission.load, content, "f.yaml", base_revision=0)


def test_mission_does_not_alias_its_start_content(library: Any, new_mission_factory: Any) -> None:
    start = MissionContent.empty(library)
    first = new_mission_factory(content=start)
    second = new_mission_factory(content=start)
    first.add_skill("alpha", "move")
    assert start.tasks["alpha"] == []
    assert second.state.task("alpha") == []


# -- revisions, events, stale requests --------------------------------------------


def operator_requests(drv: Any) -> list[tuple[EventKind, str, Any, dict[str, Any]]]:
    """Every operator request, each valid in the state the previous ones leave."""
    mission = drv.mission
    a1, a2 = drv.adds("alpha", 2)
    b1 = drv.add("bravo")
    drv.add("alpha")
    return [
        (EventKind.SKILL_ADDED, "add_skill", ("alpha", "move"), {}),
        (EventKind.SKILL_EDITED, "edit_skill", (a1,), {"label": "x"}),
        (
            EventKind.SKILLS_REORDERED,
            "reorder",
            ("alpha", lambda: [a2, a1, *drv.ids("alpha")[2:]]),
            {},
        ),
        (EventKind.BARRIER_ADDED, "add_barrier", ([a2, b1],), {}),
        (EventKind.MARKER_ADDED, "add_marker", (TaskMarker("m", MarkerType.POSE, Pose()),), {}),
        (EventKind.MARKER_MOVED, "move_marker", ("m", Pose(1.0)), {}),
        (EventKind.MARKER_RENAMED, "rename_marker", ("m", "n"), {}),
        (EventKind.MARKER_DELETED, "delete_marker", ("n",), {}),
        (EventKind.SKILL_DELETED, "delete_skills", ([a1],), {}),
        (EventKind.BARRIER_DELETED, "delete_barrier", (lambda: mission.state.barriers[0].id,), {}),
        (EventKind.SYNC_REQUESTED, "synchronize", ("alpha",), {}),
        (EventKind.SYNC_CONFIRMED, "confirm_synchronized", ("alpha", [a2]), {}),
        (
            EventKind.SYNC_DECLINED,
            "decline_synchronize",
            ("alpha", lambda: drv.ids("alpha")[1:], "no"),
            {},
        ),
        (EventKind.SYNC_REQUESTED, "synchronize", ("alpha",), {}),
        (EventKind.UPLOAD_CANCELLED, "cancel_uploads", ("alpha",), {}),
        (EventKind.UNSYNC_REQUESTED, "unsynchronize", ("alpha",), {}),
        (EventKind.UNSYNC_CONFIRMED, "confirm_unsynchronized", ("alpha", []), {}),
        (EventKind.STATUS_CHANGED, "report_status", (a2, S.SYNCWAITING), {}),
        (EventKind.SKILL_STOPPED, "stop", ("alpha",), {}),
        (EventKind.STATUS_CHANGED, "report_status", (a2, S.FAILURE), {}),
        (EventKind.SKILL_RETRIED, "retry", (a2,), {}),
        (EventKind.STATUS_CHANGED, "report_status", (lambda: drv.ids("alpha")[1], S.FAILURE), {}),
        (EventKind.SKILL_SKIPPED, "skip", (lambda: drv.ids("alpha")[1],), {}),
        (EventKind.MISSION_REPLACED, "new_mission", (), {}),
        (EventKind.MISSION_REPLACED, "load", (MissionContent.empty(mission.library), "f"), {}),
    ]


# Robot answers carry no base revision.
ROBOT_SIDE = {
    "confirm_synchronized",
    "decline_synchronize",
    "confirm_unsynchronized",
    "report_status",
}


def _resolve(args: tuple[Any, ...]) -> tuple[Any, ...]:
    return tuple(arg() if callable(arg) else arg for arg in args)


def test_every_operation_emits_one_event_and_one_revision(
    mission: Any, drv: Any, accepted: Any, rejected: Any, clock: Any
) -> None:
    requests = operator_requests(drv)
    seen = set()
    for kind, name, args, kwargs in requests:
        args = _resolve(args)
        operation = getattr(mission, name)
        if name not in ROBOT_SIDE:
            # Stale: made before the latest operator change (robot progress alone is not).
            stale = mission.operator_revision - 1
            error = rejected(
                mission, StaleRevision, operation, *args, base_revision=stale, **kwargs
            )
            assert (error.base_revision, error.current_revision) == (stale, mission.revision)
            assert f"revision {stale}" in str(error)
            assert f"revision {mission.revision}" in str(error)
            rejected(mission, StaleRevision, operation, *args, base_revision=10**6, **kwargs)
            kwargs = {**kwargs, "base_revision": mission.revision}
        clock.now += 1.0
        event = accepted(mission, kind, operation, *args, **kwargs)
        assert event.stamp == clock.now
        seen.add(kind)
    assert seen == set(EventKind)


def test_replay_rebuilds_the_mission_after_every_step(
    drv: Any, new_mission_factory: Any, snap: Any
) -> None:
    recorded = drv.mission
    requests = operator_requests(drv)
    base, base_revision = recorded.state.content(), recorded.revision
    events = []
    for _kind, name, args, kwargs in requests:
        events.append(getattr(recorded, name)(*_resolve(args), **kwargs))
        # Replaying everything after each step also catches an event whose content
        # the original mission changed afterwards.
        fresh = new_mission_factory(content=base, revision=base_revision)
        for event in events:
            fresh.replay(event)
        assert snap(fresh) == snap(recorded)
        assert fresh.revision == recorded.revision


def test_replay_of_a_scenario_with_barriers_and_markers(
    mission: Any, drv: Any, new_mission_factory: Any, snap: Any
) -> None:
    events = []

    def record(event: Any) -> Any:
        events.append(event)
        return event

    mission.add_marker(TaskMarker("goal", MarkerType.POSE, Pose(1.0)))
    record_all = [
        lambda: mission.add_skill("alpha", "move", bindings={"target": "goal"}),
        lambda: mission.add_skill("bravo", "scan", {"passes": 2}),
        lambda: mission.add_skill("alpha", "noop", index=0),
        lambda: mission.add_barrier([drv.ids("alpha")[1], drv.ids("bravo")[0]]),
        lambda: mission.move_marker("goal", Pose(4.0, 4.0)),
        lambda: mission.synchronize("bravo"),
        lambda: mission.confirm_synchronized("bravo", drv.ids("bravo")),
        lambda: mission.report_status(drv.ids("bravo")[0], S.SYNCWAITING, stamp=5.0),
        lambda: mission.rename_marker("goal", "target"),
        lambda: mission.stop("bravo"),
        lambda: mission.unsynchronize("bravo"),
        lambda: mission.confirm_unsynchronized("bravo", drv.ids("bravo")),
        lambda: mission.new_mission(),
        lambda: mission.add_skill("alpha", "move", bindings={"target": "target"}),
        lambda: mission.add_skill("alpha", "move"),
        lambda: mission.reorder("alpha", list(reversed(drv.ids("alpha")))),
    ]
    start = mission.state.content()
    start_revision = mission.revision
    for step in record_all:
        record(step())
    fresh = new_mission_factory(content=start, revision=start_revision)
    for event in events:
        fresh.replay(event)
    assert snap(fresh) == snap(mission)
    assert fresh.revision == mission.revision
    # The replayed mission is independent of the original.
    mission.add_skill("charlie", "noop")
    assert fresh.state.task("charlie") == []


def test_replay_refuses_an_event_out_of_sequence(
    mission: Any, drv: Any, new_mission_factory: Any, rejected: Any
) -> None:
    events = [mission.add_skill("alpha", "move") for _ in range(3)]
    fresh = new_mission_factory()
    rejected(fresh, RuleViolation, fresh.replay, events[1], match="revision 2")
    fresh.replay(events[0])
    rejected(fresh, RuleViolation, fresh.replay, events[0], match="does not follow revision 1")
    rejected(fresh, RuleViolation, fresh.replay, events[2])
    fresh.replay(events[1])
    fresh.replay(events[2])
    assert [s.id for s in fresh.state.task("alpha")] == drv.ids("alpha")


def test_id_factory_that_repeats_itself(library: Any, rejected: Any) -> None:
    mission = Mission(library, new_id=lambda prefix: "same")
    mission.add_skill("alpha", "move")
    rejected(mission, RuleViolation, mission.add_skill, "alpha", "move", match="free id")


def test_robot_progress_does_not_make_an_operator_view_stale(mission: Any) -> None:
    """Reports bump the revision, but an operator request made before them still goes through."""
    first = mission.add_skill("alpha", "noop").change.put_skills[0].skill.id
    mission.add_skill("alpha", "noop")
    mission.synchronize("alpha", first)
    view = mission.revision
    mission.confirm_synchronized("alpha", [first])
    mission.report_status(first, SkillStatus.RUNNING)
    assert mission.revision == view + 2
    event = mission.add_skill("alpha", "noop", base_revision=view)
    assert event.revision == view + 3
    with pytest.raises(StaleRevision):
        mission.add_skill("alpha", "noop", base_revision=view)  # another operator's add came since


def test_cancelling_an_unanswered_upload_returns_the_skills_to_the_blueprint(
    mission: Any,
) -> None:
    first = mission.add_skill("alpha", "noop").change.put_skills[0].skill.id
    second = mission.add_skill("alpha", "noop").change.put_skills[0].skill.id
    mission.synchronize("alpha")
    event = mission.cancel_uploads("alpha", base_revision=mission.revision)
    assert event.kind is EventKind.UPLOAD_CANCELLED
    assert [p.skill.id for p in event.change.put_skills] == [first, second]
    for skill_id in (first, second):
        skill = mission.state.skill(skill_id)
        assert skill.is_editable and skill.status_text == "upload cancelled by the operator"
    with pytest.raises(RuleViolation):
        mission.cancel_uploads("alpha")  # nothing pending any more
    mission.edit_skill(first, label="edited after the cancel")


def test_a_skill_sent_again_after_a_cancelled_upload_no_longer_says_cancelled(
    mission: Any,
) -> None:
    # Sync, take back, sync again (during a cut): the second upload is delivered and runs.
    skill_id = mission.add_skill("alpha", "noop").change.put_skills[0].skill.id
    mission.synchronize("alpha")
    mission.cancel_uploads("alpha")
    mission.synchronize("alpha")
    assert mission.state.skill(skill_id).status_text == "", "uploading, nothing cancelled"
    mission.confirm_synchronized("alpha", [skill_id])
    mission.report_status(skill_id, SkillStatus.RUNNING)
    skill = mission.state.skill(skill_id)
    assert (skill.status, skill.status_text) == (SkillStatus.RUNNING, "")


def test_taking_back_the_later_of_two_waiting_uploads_keeps_the_first(mission: Any) -> None:
    first = mission.add_skill("alpha", "noop").change.put_skills[0].skill.id
    second = mission.add_skill("alpha", "noop").change.put_skills[0].skill.id
    mission.synchronize("alpha")
    event = mission.cancel_uploads("alpha", second)
    assert [p.skill.id for p in event.change.put_skills] == [second]
    assert mission.state.skill(first).transfer is Transfer.UPLOADING
    assert mission.state.skill(second).is_editable
    mission.confirm_synchronized("alpha", [first])
    assert mission.state.skill(first).status is SkillStatus.IDLE_SYNCHRONIZED


def test_area_parameters_must_be_polygons(mission: Any) -> None:
    from rosmc_server.core import InvalidRequest

    for bad in ([1, 2, 3], [{"x": 0, "y": 0}, {"x": 1, "y": 0}], [{"x": 0}, {"x": 1}, {"y": 2}]):
        with pytest.raises(InvalidRequest):
            mission.add_skill("alpha", "scan", {"area": bad})
