"""Robot status reports, stop, retry and skip."""

from __future__ import annotations

import itertools
import math
from typing import Any

import pytest

from rosmc_server.core import (
    EventKind,
    InvalidRequest,
    MarkerType,
    MissionState,
    NotFound,
    Pose,
    Resolution,
    RuleViolation,
    SkillStatus,
    StaleRevision,
    TaskMarker,
    Transfer,
)
from rosmc_server.core.live.updates import BarrierPut, BarrierRemoved, apply_event
from rosmc_server.core.robots.commands import CommandKind, commands_for_event

S = SkillStatus

# The robot's legal status changes (the specification, written out independently
# of the core's table). Same-status reports are covered separately.
LEGAL = {
    S.IDLE_SYNCHRONIZED: {S.SYNCWAITING, S.RUNNING, S.FAILURE},
    S.SYNCWAITING: {S.RUNNING, S.PAUSED, S.IDLE_SYNCHRONIZED, S.FAILURE},
    S.RUNNING: {S.PAUSED, S.SUCCESS, S.FAILURE, S.IDLE_SYNCHRONIZED},
    S.PAUSED: {S.RUNNING, S.SYNCWAITING, S.IDLE_SYNCHRONIZED, S.FAILURE},
    S.SUCCESS: set(),
    S.FAILURE: set(),
}

# How to bring a freshly synchronized skill into each status.
PATH = {
    S.IDLE_SYNCHRONIZED: [],
    S.SYNCWAITING: [S.SYNCWAITING],
    S.RUNNING: [S.RUNNING],
    S.PAUSED: [S.RUNNING, S.PAUSED],
    S.SUCCESS: [S.RUNNING, S.SUCCESS],
    S.FAILURE: [S.RUNNING, S.FAILURE],
}


@pytest.fixture
def synced(mission: Any, drv: Any) -> list[str]:
    """Three synchronized skills on alpha."""
    ids = drv.adds("alpha", 3)
    drv.sync("alpha")
    return ids


def bring(mission: Any, skill_id: str, status: SkillStatus) -> None:
    for step in PATH[status]:
        mission.report_status(skill_id, step)


# -- status reports ---------------------------------------------------------------

PAIRS = [
    (before, after)
    for before, after in itertools.product(PATH, S)
    if before is not after or before.is_final or before is S.IDLE_SYNCHRONIZED
]


@pytest.mark.parametrize(("before", "after"), PAIRS, ids=[f"{b.name}->{a.name}" for b, a in PAIRS])
def test_transition_table(
    mission: Any, drv: Any, accepted: Any, rejected: Any, synced: list[str], before: Any,
    after: Any,
) -> None:  # fmt: skip
    first = synced[0]
    bring(mission, first, before)
    if after in LEGAL[before]:
        event = accepted(mission, EventKind.STATUS_CHANGED, mission.report_status, first, after)
        assert drv.status(first) is after
        assert f"{before.name} -> {after.name}" in event.summary
        assert event.agent == "alpha"
    else:
        rejected(mission, RuleViolation, mission.report_status, first, after, match=before.name)


def test_success_cannot_become_running_and_finals_are_immutable(
    mission: Any, drv: Any, rejected: Any, synced: list[str]
) -> None:
    done, failed, _ = synced
    drv.finish(done)
    drv.finish(failed, S.FAILURE)
    rejected(mission, RuleViolation, mission.report_status, done, S.RUNNING, match="SUCCESS")
    for skill_id, final in ((done, S.SUCCESS), (failed, S.FAILURE)):
        for status in S:
            rejected(mission, RuleViolation, mission.report_status, skill_id, status)
        rejected(mission, RuleViolation, mission.report_status, skill_id, final, text="new")
        rejected(mission, RuleViolation, mission.report_status, skill_id, final, attempt=2)


def test_report_for_unknown_or_unsynchronized_skill(mission: Any, drv: Any, rejected: Any) -> None:
    rejected(mission, NotFound, mission.report_status, "ghost", S.RUNNING, match="'ghost'")
    blueprint, uploading = drv.adds("alpha", 2)
    mission.synchronize("alpha", uploading)
    mission.decline_synchronize("alpha", [uploading], "later")
    mission.synchronize("alpha")
    # blueprint is now uploading too; a third skill stays in the blueprint.
    idle = drv.add("alpha")
    for skill_id in (blueprint, uploading, idle):
        rejected(
            mission, RuleViolation, mission.report_status, skill_id, S.RUNNING,
            match="not synchronized",
        )  # fmt: skip


def test_out_of_order_report_is_refused(
    mission: Any, drv: Any, rejected: Any, synced: list[str]
) -> None:
    s1, s2, s3 = synced
    for status in (S.RUNNING, S.SYNCWAITING, S.FAILURE):
        rejected(mission, RuleViolation, mission.report_status, s2, status, match=f"'{s1}'")
    drv.run(s1)
    rejected(mission, RuleViolation, mission.report_status, s2, S.RUNNING, match="RUNNING")
    drv.finish(s1)
    drv.run(s2)
    rejected(mission, RuleViolation, mission.report_status, s3, S.RUNNING, match=f"'{s2}'")
    mission.report_status(s2, S.FAILURE)
    # An unresolved failure blocks the rest of the task until retried or skipped.
    rejected(mission, RuleViolation, mission.report_status, s3, S.RUNNING, match="FAILURE")
    mission.skip(s2)
    drv.finish(s3)


def test_progress_text_and_attempt_updates(
    mission: Any, drv: Any, accepted: Any, rejected: Any, synced: list[str]
) -> None:
    first = synced[0]
    drv.run(first)
    event = accepted(
        mission, EventKind.STATUS_CHANGED, mission.report_status, first, S.RUNNING, text="50 %"
    )
    assert "50 %" in event.summary
    assert mission.state.skill(first).status_text == "50 %"
    # The same report again changes nothing.
    rejected(
        mission, RuleViolation, mission.report_status, first, S.RUNNING, text="50 %",
        match="changes nothing",
    )  # fmt: skip
    # The robot retries on its own: a higher attempt is news.
    mission.report_status(first, S.RUNNING, attempt=2, text="50 %")
    assert mission.state.skill(first).attempt == 2
    rejected(mission, RuleViolation, mission.report_status, first, S.RUNNING, attempt=1)
    mission.report_status(first, S.PAUSED)
    mission.report_status(first, S.PAUSED, text="waiting for light")


@pytest.mark.parametrize(
    ("kwargs", "fragment"),
    [
        ({"attempt": 1.5}, "attempt"),
        ({"attempt": True}, "attempt"),
        ({"attempt": 0}, "attempt"),
        ({"stamp": math.nan}, "stamp"),
        ({"stamp": math.inf}, "stamp"),
        ({"stamp": -1.0}, "stamp"),
        ({"text": 5}, "text"),
    ],
)
def test_malformed_reports_are_refused(
    mission: Any, rejected: Any, synced: list[str], kwargs: Any, fragment: str
) -> None:
    with pytest.raises(InvalidRequest, match=fragment):
        mission.report_status(synced[0], S.RUNNING, **kwargs)
    rejected(mission, InvalidRequest, mission.report_status, synced[0], S.RUNNING, **kwargs)


def test_report_status_must_be_a_status(mission: Any, rejected: Any, synced: list[str]) -> None:
    rejected(mission, InvalidRequest, mission.report_status, synced[0], 3)
    rejected(mission, InvalidRequest, mission.report_status, synced[0], "RUNNING")


def test_timestamps(mission: Any, drv: Any, clock: Any, synced: list[str]) -> None:
    first = synced[0]
    clock.now = 10.0
    mission.report_status(first, S.SYNCWAITING)
    assert mission.state.skill(first).started == 10.0
    clock.now = 20.0
    mission.report_status(first, S.RUNNING)
    mission.report_status(first, S.PAUSED, stamp=25.0)
    mission.report_status(first, S.RUNNING)
    assert mission.state.skill(first).started == 10.0
    mission.report_status(first, S.SUCCESS, stamp=30.0)
    skill = mission.state.skill(first)
    assert (skill.started, skill.finished) == (10.0, 30.0)


def test_robot_may_put_a_skill_back(mission: Any, drv: Any, synced: list[str]) -> None:
    first = synced[0]
    drv.run(first)
    mission.report_status(first, S.IDLE_SYNCHRONIZED, text="preempted")
    skill = mission.state.skill(first)
    assert skill.status is S.IDLE_SYNCHRONIZED and skill.started == 0.0
    drv.finish(first)


# -- stop ------------------------------------------------------------------------


@pytest.mark.parametrize("active", [S.RUNNING, S.PAUSED, S.SYNCWAITING])
def test_stop_puts_the_active_skill_back(
    mission: Any, drv: Any, accepted: Any, synced: list[str], active: Any
) -> None:
    first = synced[0]
    bring(mission, first, active)
    event = accepted(mission, EventKind.SKILL_STOPPED, mission.stop, "alpha")
    assert event.agent == "alpha" and first in event.summary
    skill = mission.state.skill(first)
    assert (skill.status, skill.started, skill.status_text) == (S.IDLE_SYNCHRONIZED, 0.0, "stopped")
    assert [drv.status(i) for i in synced[1:]] == [S.IDLE_SYNCHRONIZED] * 2
    drv.finish(first)  # it runs again next time


def test_stop_without_an_active_skill(
    mission: Any, drv: Any, rejected: Any, synced: list[str]
) -> None:
    rejected(mission, RuleViolation, mission.stop, "alpha", match="no running")
    rejected(mission, RuleViolation, mission.stop, "bravo", match="no running")
    rejected(mission, NotFound, mission.stop, "zulu")
    drv.finish(synced[0])
    drv.finish(synced[1], S.FAILURE)
    rejected(mission, RuleViolation, mission.stop, "alpha", match="no running")


def test_stop_on_stale_revision(mission: Any, drv: Any, rejected: Any, synced: list[str]) -> None:
    drv.run(synced[0])
    error = rejected(mission, StaleRevision, mission.stop, "alpha", base_revision=2)
    assert str(mission.revision) in str(error) and "revision 2" in str(error)
    mission.stop("alpha", base_revision=mission.revision)


# -- retry -----------------------------------------------------------------------


def test_retry_makes_a_fresh_instance_right_after(
    mission: Any, drv: Any, accepted: Any, clock: Any
) -> None:
    mission.add_marker(TaskMarker("goal", MarkerType.POSE, Pose(5.0, 5.0)))
    first = drv.add("alpha", "move", params={"speed": 1.5}, label="go", bindings={"target": "goal"})
    second = drv.add("alpha")
    drv.sync("alpha")
    clock.now = 50.0
    drv.finish(first, S.FAILURE)
    before = mission.state.skill(first)
    event = accepted(mission, EventKind.SKILL_RETRIED, mission.retry, first)
    fresh_id = event.change.put_skills[1].skill.id
    assert fresh_id not in (first, second)
    assert drv.ids("alpha") == [first, fresh_id, second]
    original, fresh = mission.state.skill(first), mission.state.skill(fresh_id)
    assert original.status is S.FAILURE and original.resolution is Resolution.RETRIED
    assert original.params == before.params and original.finished == 50.0
    assert fresh.status is S.IDLE_SYNCHRONIZED and fresh.transfer is Transfer.NONE
    assert fresh.attempt == before.attempt + 1
    assert fresh.params == before.params and fresh.label == "go"
    assert fresh.bindings == {"target": "goal"}
    assert (fresh.started, fresh.finished, fresh.status_text) == (0.0, 0.0, "")
    assert fresh.resolution is Resolution.NONE
    assert f"attempt {fresh.attempt}" in event.summary
    # The fresh instance runs next; a retry of the retry counts on.
    with pytest.raises(RuleViolation, match="cannot progress"):
        mission.report_status(second, S.RUNNING)
    drv.finish(fresh_id, S.FAILURE)
    third = mission.retry(fresh_id).change.put_skills[1].skill
    assert third.attempt == 3
    assert drv.ids("alpha") == [first, fresh_id, third.id, second]


def test_retry_refusals(mission: Any, drv: Any, rejected: Any, synced: list[str]) -> None:
    done, failed, waiting = synced
    blueprint = drv.add("alpha")
    rejected(mission, NotFound, mission.retry, "ghost")
    drv.finish(done)
    drv.finish(failed, S.FAILURE)
    for skill_id, state in ((done, "SUCCESS"), (waiting, "IDLE_SYNCHRONIZED"), (blueprint, "IDLE")):
        rejected(mission, RuleViolation, mission.retry, skill_id, match=state)
    mission.retry(failed)
    rejected(mission, RuleViolation, mission.retry, failed, match="already retried")
    rejected(mission, RuleViolation, mission.skip, failed, match="already retried")


def test_retry_of_running_skill_refused(
    mission: Any, drv: Any, rejected: Any, synced: list[str]
) -> None:
    drv.run(synced[0])
    rejected(mission, RuleViolation, mission.retry, synced[0], match="RUNNING")
    rejected(mission, RuleViolation, mission.skip, synced[0], match="RUNNING")


# -- a failed barrier member: retry and skip ------------------------------------------


@pytest.fixture
def waiting_pair(mission: Any, drv: Any) -> tuple[str, str, str]:
    """alpha's ``a`` and bravo's ``b`` in one barrier, synchronized; returns (a, b, barrier)."""
    a, b = drv.add("alpha"), drv.add("bravo")
    barrier = mission.add_barrier([a, b]).change.put_barriers[0].id
    drv.sync("alpha")
    drv.sync("bravo")
    return a, b, barrier


def fail_waiting(mission: Any, skill_id: str) -> None:
    """The robot reaches the barrier, then gives up waiting (its timeout)."""
    mission.report_status(skill_id, S.SYNCWAITING)
    mission.report_status(skill_id, S.FAILURE, text="timed out after 5 s waiting at barrier")


def test_a_member_that_failed_before_the_release_hands_its_place_to_the_retry(
    mission: Any, drv: Any, accepted: Any, waiting_pair: tuple[str, str, str]
) -> None:
    a, b, barrier = waiting_pair
    mission.report_status(b, S.SYNCWAITING)
    fail_waiting(mission, a)
    event = accepted(mission, EventKind.SKILL_RETRIED, mission.retry, a)
    fresh = event.change.put_skills[1].skill.id
    assert mission.state.barrier(barrier).skill_ids == (fresh, b)  # the order is kept
    assert mission.state.barrier_of(fresh).id == barrier
    assert mission.state.barrier_of(a) is None  # the failure stays as a log, outside
    assert event.change.put_barriers == (mission.state.barrier(barrier),)
    assert f"barrier '{barrier}' now waits for '{fresh}' (its partners on bravo" in event.summary
    # The robots hear the new barrier sets first, then the retry.
    specs = commands_for_event(event, mission.state)
    assert [(c.agent, c.kind) for c in specs] == [
        ("alpha", CommandKind.BARRIERS),
        ("bravo", CommandKind.BARRIERS),
        ("alpha", CommandKind.RETRY),
    ]
    assert specs[1].barriers == (mission.state.barrier(barrier),)
    # The partner waits on; the new attempt starts with it.
    mission.report_status(fresh, S.SYNCWAITING)
    mission.report_status(fresh, S.RUNNING)
    mission.report_status(b, S.RUNNING)


def test_a_member_that_failed_before_reaching_the_barrier_rejoins_too(
    mission: Any, waiting_pair: tuple[str, str, str]
) -> None:
    a, b, barrier = waiting_pair
    mission.report_status(a, S.FAILURE, text="could not reach the start point")
    fresh = mission.retry(a).change.put_skills[1].skill.id
    assert mission.state.barrier(barrier).skill_ids == (fresh, b)


def test_a_retry_after_the_release_runs_alone(
    mission: Any, drv: Any, waiting_pair: tuple[str, str, str]
) -> None:
    a, b, barrier = waiting_pair
    for member in (a, b):
        mission.report_status(member, S.SYNCWAITING)
        mission.report_status(member, S.RUNNING)
    mission.report_status(a, S.FAILURE)
    event = mission.retry(a)
    fresh = event.change.put_skills[1].skill.id
    assert mission.state.barrier(barrier).skill_ids == (a, b)  # the log of who started together
    assert mission.state.barrier_of(fresh) is None
    assert event.change.put_barriers == () and event.change.removed_barrier_ids == ()
    assert f"its barrier '{barrier}' had released" in event.summary
    assert "the new attempt runs alone" in event.summary
    kinds = [c.kind for c in commands_for_event(event, mission.state)]
    assert kinds == [CommandKind.RETRY]
    drv.finish(b)  # the partner finishing counts as released as well
    drv.finish(fresh)


def test_a_second_failure_of_the_fresh_instance_passes_the_place_on(
    mission: Any, waiting_pair: tuple[str, str, str]
) -> None:
    a, b, barrier = waiting_pair
    fail_waiting(mission, a)
    fresh = mission.retry(a).change.put_skills[1].skill.id
    fail_waiting(mission, fresh)
    third = mission.retry(fresh).change.put_skills[1].skill
    assert third.attempt == 3
    assert mission.state.barrier(barrier).skill_ids == (third.id, b)


def test_skipping_a_failed_member_dissolves_a_two_member_barrier(
    mission: Any, accepted: Any, waiting_pair: tuple[str, str, str]
) -> None:
    a, b, barrier = waiting_pair
    mission.report_status(b, S.SYNCWAITING)
    fail_waiting(mission, a)
    event = accepted(mission, EventKind.SKILL_SKIPPED, mission.skip, a)
    assert mission.state.barriers == ()
    assert event.change.removed_barrier_ids == (barrier,)
    assert f"barrier '{barrier}' is dissolved, so bravo goes on alone" in event.summary
    specs = commands_for_event(event, mission.state)
    assert [(c.agent, c.kind, c.barriers) for c in specs] == [
        ("alpha", CommandKind.BARRIERS, ()),
        ("bravo", CommandKind.BARRIERS, ()),
        ("alpha", CommandKind.SKIP, ()),
    ]
    mission.report_status(b, S.RUNNING)  # the partner is free to go


def test_skipping_a_failed_member_of_three_leaves_the_others_together(
    mission: Any, drv: Any, waiting_pair: tuple[str, str, str]
) -> None:
    a, b, _ = waiting_pair
    mission.delete_barrier(mission.state.barrier_of(a).id)
    c = drv.add("charlie")
    drv.sync("charlie")
    barrier = mission.add_barrier([a, b, c]).change.put_barriers[0].id
    fail_waiting(mission, a)
    event = mission.skip(a)
    assert mission.state.barrier(barrier).skill_ids == (b, c)
    assert "whose other members (bravo, charlie) still start together" in event.summary


def test_skipping_a_member_that_failed_after_the_release_keeps_the_barrier(
    mission: Any, drv: Any, waiting_pair: tuple[str, str, str]
) -> None:
    a, b, barrier = waiting_pair
    drv.run(a)
    drv.run(b)
    drv.finish(a, S.FAILURE)
    event = mission.skip(a)
    assert mission.state.barrier(barrier).skill_ids == (a, b)
    assert event.change.put_barriers == () and event.summary.endswith("skipped")


def test_the_barrier_change_of_a_retry_and_a_skip_replays_identically(
    mission: Any, waiting_pair: tuple[str, str, str]
) -> None:
    a, b, _ = waiting_pair
    start = MissionState(mission.state.content(), mission.revision)
    described = MissionState(mission.state.content(), mission.revision)
    events = [
        mission.report_status(a, S.SYNCWAITING),
        mission.report_status(a, S.FAILURE),
    ]
    events.append(mission.retry(a))
    fresh = events[-1].change.put_skills[1].skill.id
    events += [
        mission.report_status(fresh, S.SYNCWAITING),
        mission.report_status(fresh, S.FAILURE),
        mission.skip(fresh),
    ]
    puts, removed = [], []
    for event in events:
        apply_event(start, event)
        for change in apply_event(described, event):
            if isinstance(change, BarrierPut):
                puts.append((change.old.skill_ids if change.old else None, change.new.skill_ids))
            if isinstance(change, BarrierRemoved):
                removed.append(change.barrier.skill_ids)
    for state in (start, described):
        assert state.content() == mission.state.content()
        assert state.revision == mission.revision
    assert puts == [((a, b), (fresh, b))]
    assert removed == [(fresh, b)]


def test_retry_on_stale_revision(mission: Any, drv: Any, rejected: Any, synced: list[str]) -> None:
    drv.finish(synced[0], S.FAILURE)
    rejected(mission, StaleRevision, mission.retry, synced[0], base_revision=0)


# -- skip ------------------------------------------------------------------------


def test_skip(mission: Any, drv: Any, accepted: Any, synced: list[str]) -> None:
    failed, later, _ = synced
    drv.finish(failed, S.FAILURE)
    event = accepted(mission, EventKind.SKILL_SKIPPED, mission.skip, failed)
    assert event.agent == "alpha" and failed in event.summary
    skill = mission.state.skill(failed)
    assert skill.status is S.FAILURE and skill.resolution is Resolution.SKIPPED
    assert drv.ids("alpha") == synced
    drv.finish(later)


def test_skip_refusals(mission: Any, drv: Any, rejected: Any, synced: list[str]) -> None:
    done, failed, waiting = synced
    rejected(mission, NotFound, mission.skip, "ghost")
    drv.finish(done)
    drv.finish(failed, S.FAILURE)
    rejected(mission, RuleViolation, mission.skip, done, match="SUCCESS")
    rejected(mission, RuleViolation, mission.skip, waiting, match="IDLE_SYNCHRONIZED")
    rejected(mission, StaleRevision, mission.skip, failed, base_revision=1)
    mission.skip(failed)
    rejected(mission, RuleViolation, mission.skip, failed, match="already skipped")
    rejected(mission, RuleViolation, mission.retry, failed, match="already skipped")
