"""The executor's queue changes as pure functions: upload, unsync, retry, skip, adopt."""

from __future__ import annotations

from dataclasses import replace
from typing import Any

from rosmc_server.core import Resolution, SkillInstance, SkillStatus, Transfer
from rosmc_server.executor.core import queueing

S = SkillStatus


def skill(skill_id: str, status: SkillStatus = S.IDLE, **fields: Any) -> SkillInstance:
    return SkillInstance(skill_id, "r1", "wait", "wait", {"duration": 1.0}, status=status, **fields)


def held(*ids: str) -> list[SkillInstance]:
    return [skill(i, S.IDLE_SYNCHRONIZED) for i in ids]


def ids(queue: list[SkillInstance]) -> list[str]:
    return [s.id for s in queue]


def nothing_wrong(candidate: SkillInstance) -> str:
    return ""


def refuse(*bad: str) -> queueing.Checker:
    return lambda candidate: f"cannot run {candidate.id}" if candidate.id in bad else ""


# -- upload --------------------------------------------------------------------
def test_upload_appends_held_copies() -> None:
    sent = [skill("a", transfer=Transfer.UPLOADING), skill("b", S.RUNNING)]
    answer = queueing.upload(held("x"), sent, nothing_wrong)
    assert ids(answer.queue) == ["x", "a", "b"]
    assert all((s.status, s.transfer) == (S.IDLE_SYNCHRONIZED, Transfer.NONE) for s in answer.queue)
    assert answer.accepted == ("a", "b")
    assert (answer.rejected, answer.reasons) == ((), ())


def test_upload_refuses_everything_after_a_refused_skill() -> None:
    answer = queueing.upload([], [skill("a"), skill("b"), skill("c")], refuse("b"))
    assert ids(answer.queue) == ["a"]
    assert answer.accepted == ("a",)
    assert answer.rejected == ("b", "c")
    assert answer.reasons == ("cannot run b", "follows refused skill 'b'")


def test_upload_accepts_a_skill_already_held_unchanged() -> None:
    queue = [skill("a", S.RUNNING)]
    answer = queueing.upload(queue, [skill("a"), skill("b")], refuse("a"))
    assert answer.queue[0] is queue[0]  # not reset, not checked again
    assert answer.accepted == ("a", "b")


def test_upload_does_not_change_its_input() -> None:
    queue = held("a")
    queueing.upload(queue, [skill("b")], nothing_wrong)
    assert ids(queue) == ["a"]


# -- unsync ------------------------------------------------------------------------
def test_unsync_removes_the_not_started_tail() -> None:
    queue = [skill("a", S.SUCCESS), *held("b", "c")]
    answer = queueing.unsync(queue, ["b", "c"], active_id="")
    assert ids(answer.queue) == ["a"]
    assert answer.accepted == ("b", "c") and answer.rejected == ()


def test_unsync_keeps_the_started_skill_and_what_was_requested_before_it() -> None:
    queue = [*held("a"), skill("b", S.RUNNING), *held("c", "d")]
    answer = queueing.unsync(queue, ["a", "b", "c", "d"], active_id="b")
    assert ids(answer.queue) == ["a", "b"]
    assert answer.accepted == ("c", "d")
    assert answer.rejected == ("a", "b")
    assert answer.reasons == ("it had started", "it had started")


def test_unsync_treats_the_active_skill_as_started_even_if_idle_synchronized() -> None:
    answer = queueing.unsync(held("a", "b"), ["a", "b"], active_id="a")
    assert ids(answer.queue) == ["a"] and answer.accepted == ("b",)


def test_unsync_counts_ids_no_longer_held_as_removed() -> None:
    answer = queueing.unsync(held("a"), ["a", "gone"], active_id="")
    assert answer.queue == [] and answer.accepted == ("a", "gone")


def test_unsync_of_nothing_changes_nothing() -> None:
    queue = held("a")
    answer = queueing.unsync(queue, [], active_id="")
    assert answer.queue == queue and answer.accepted == answer.rejected == ()


# -- retry and skip ---------------------------------------------------------------------
def test_retry_marks_the_failure_and_holds_the_fresh_instance_after_it() -> None:
    queue = [skill("a", S.FAILURE), *held("b")]
    fresh = skill("a2", attempt=2, transfer=Transfer.UPLOADING)
    answer = queueing.retry(queue, "a", fresh)
    assert ids(answer.queue) == ["a", "a2", "b"]
    assert answer.queue[0].resolution is Resolution.RETRIED
    assert answer.queue[0].status is S.FAILURE
    assert (answer.queue[1].status, answer.queue[1].attempt) == (S.IDLE_SYNCHRONIZED, 2)
    assert answer.accepted == ("a2",)


def test_retry_twice_inserts_once() -> None:
    first = queueing.retry([skill("a", S.FAILURE)], "a", skill("a2"))
    # The same retry again (the failure is now RETRIED, but still a FAILURE).
    again = queueing.retry(first.queue, "a", skill("a2"))
    assert ids(again.queue) == ["a", "a2"]


def test_retry_and_skip_refuse_anything_but_a_failure() -> None:
    queue = [skill("a", S.SUCCESS), *held("b")]
    for target in ("a", "b", "ghost"):
        retried = queueing.retry(queue, target, skill("n"))
        skipped = queueing.skip(queue, target)
        assert retried.queue == skipped.queue == queue
        assert retried.rejected == skipped.rejected == (target,)
        assert retried.reasons == ("nothing to retry",)
        assert skipped.reasons == ("nothing to skip",)


def test_skip_marks_the_failure() -> None:
    answer = queueing.skip([skill("a", S.FAILURE), *held("b")], "a")
    assert answer.queue[0].resolution is Resolution.SKIPPED
    assert answer.accepted == ("a",)
    assert queueing.upcoming(answer.queue) == answer.queue[1]


# -- upcoming and holding ---------------------------------------------------------------
def test_upcoming_passes_successes_and_resolved_failures() -> None:
    queue = [
        skill("a", S.SUCCESS),
        skill("b", S.FAILURE, resolution=Resolution.SKIPPED),
        skill("c", S.FAILURE, resolution=Resolution.RETRIED),
        skill("d", S.RUNNING),
        *held("e"),
    ]
    assert queueing.upcoming(queue) == queue[3]
    assert queueing.holding(queue) is None
    assert queueing.upcoming(queue[:3]) is None


def test_holding_is_the_unresolved_failure() -> None:
    queue = [skill("a", S.SUCCESS), skill("b", S.FAILURE), *held("c")]
    assert queueing.holding(queue) == queue[1]
    assert queueing.holding(held("a")) is None
    assert queueing.holding([]) is None


# -- adopt (the ground's repair) ----------------------------------------------------------
def test_adopt_takes_the_grounds_order_and_new_skills() -> None:
    queue = held("a", "b")
    answer = queueing.adopt(queue, [skill("b"), skill("c"), skill("a")], nothing_wrong)
    assert ids(answer.queue) == ["b", "c", "a"]
    assert answer.queue[1].status is S.IDLE_SYNCHRONIZED
    assert answer.accepted == ("b", "c", "a")


def test_adopt_keeps_the_robots_own_status_of_skills_it_holds() -> None:
    queue = [skill("a", S.SUCCESS), skill("b", S.RUNNING)]
    ground = [skill("a", S.IDLE_SYNCHRONIZED), skill("b", S.IDLE_SYNCHRONIZED)]
    answer = queueing.adopt(queue, ground, nothing_wrong)
    assert answer.queue == queue


def test_adopt_keeps_active_skills_the_ground_left_out_and_drops_the_rest() -> None:
    queue = [
        skill("done", S.SUCCESS),
        skill("failed", S.FAILURE),
        skill("run", S.RUNNING),
        skill("wait", S.SYNCWAITING),
        *held("idle"),
    ]
    answer = queueing.adopt(queue, [skill("new")], nothing_wrong)
    assert ids(answer.queue) == ["run", "wait", "new"]


def test_adopt_of_a_new_empty_mission_leaves_nothing() -> None:
    queue = [skill("done", S.SUCCESS), skill("skipped", S.FAILURE, resolution=Resolution.SKIPPED)]
    assert queueing.adopt(queue, [], nothing_wrong).queue == []


def test_adopt_leaves_out_what_the_robot_cannot_run() -> None:
    answer = queueing.adopt([], [skill("a"), skill("bad"), skill("c")], refuse("bad"))
    assert ids(answer.queue) == ["a", "c"]


def test_adopt_keeps_the_grounds_finished_logs_as_they_are() -> None:
    """A robot that lost its state must not run again what the ground logged as done."""
    ground = [
        skill("a", S.SUCCESS, started=5.0, finished=6.0),
        skill("b", S.FAILURE, resolution=Resolution.SKIPPED, status_text="broke"),
        skill("c", S.RUNNING, started=7.0),
        skill("d", S.IDLE_SYNCHRONIZED, transfer=Transfer.REMOVING),
    ]
    answer = queueing.adopt([], ground, nothing_wrong)
    assert [s.status for s in answer.queue] == [
        S.SUCCESS,
        S.FAILURE,
        S.IDLE_SYNCHRONIZED,
        S.IDLE_SYNCHRONIZED,
    ]
    assert answer.queue[0] == replace(ground[0], transfer=Transfer.NONE)
    assert answer.queue[1].resolution is Resolution.SKIPPED
    assert all(s.transfer is Transfer.NONE for s in answer.queue)
    assert queueing.upcoming(answer.queue) == answer.queue[2]
