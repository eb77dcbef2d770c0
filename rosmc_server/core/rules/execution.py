"""Execution-side operations: synchronize, unsynchronize, robot reports, stop, retry, skip.

Synchronization is a two-step exchange with the robot: the ground marks
skills as being uploaded (or removed), and they change section only when the
robot confirms. Robot status reports are checked against the legal transitions
and the task order, so the ground never shows an impossible history.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import replace

from ..errors import InvalidRequest, RuleViolation
from ..model.changes import Change, EventKind, PlacedSkill, Proposal
from ..model.model import Resolution, SkillInstance, SkillStatus, Transfer, skill_with
from ..model.state import MissionState
from ..robots.commands import CommandKind
from ..validation import clip_status_text, excerpt
from ..views.vocabulary import counted
from .barriers import after_retry, after_skip
from .legality import (
    TaskView,
    failure_refusal,
    sync_refusal,
    take_back_refusal,
    unsync_start,
)

S = SkillStatus

# Status changes a robot may report, from -> allowed targets. Reporting the
# same active status again updates attempt or progress text.
REPORTABLE: Mapping[SkillStatus, frozenset[SkillStatus]] = {
    S.IDLE_SYNCHRONIZED: frozenset({S.SYNCWAITING, S.RUNNING, S.FAILURE}),
    S.SYNCWAITING: frozenset({S.SYNCWAITING, S.RUNNING, S.PAUSED, S.IDLE_SYNCHRONIZED, S.FAILURE}),
    S.RUNNING: frozenset({S.RUNNING, S.PAUSED, S.SUCCESS, S.FAILURE, S.IDLE_SYNCHRONIZED}),
    S.PAUSED: frozenset({S.PAUSED, S.RUNNING, S.SYNCWAITING, S.IDLE_SYNCHRONIZED, S.FAILURE}),
}


def plan_synchronize(state: MissionState, agent: str, upto_id: str | None) -> Proposal:
    """Mark ``agent``'s editable blueprint up to ``upto_id`` (all if None) as uploading."""
    task = state.task(agent)
    sections = state.sections(agent)
    refusal = sync_refusal(TaskView.live(state, agent))
    if refusal is not None:
        raise RuleViolation(refusal)
    end = len(task)
    if upto_id:
        owner, index = state.locate(upto_id)  # NotFound for an unknown id
        if owner != agent or index < sections.editable_start:
            raise RuleViolation(f"skill '{upto_id}' is not in {agent}'s editable blueprint")
        end = index + 1
    editable = task[sections.editable_start : end]
    start = sections.editable_start
    # A new upload: what an earlier one's fate left in the text (cancelled, declined) is over.
    puts = tuple(
        PlacedSkill(start + offset, skill_with(skill, transfer=Transfer.UPLOADING, status_text=""))
        for offset, skill in enumerate(editable)
    )
    return Proposal(
        EventKind.SYNC_REQUESTED,
        agent,
        f"uploading {counted(len(puts), 'skill')} to {agent}: {_ids(editable)}",
        Change(put_skills=puts),
    )


def plan_confirm_sync(state: MissionState, agent: str, skill_ids: Sequence[str]) -> Proposal:
    """The robot stored these uploading skills: they become IDLE_SYNCHRONIZED."""
    uploading = state.pending(agent, Transfer.UPLOADING)
    _require_run(uploading, skill_ids, agent, "uploads", from_front=True)
    puts = _placed(
        state,
        [
            skill_with(s, status=S.IDLE_SYNCHRONIZED, transfer=Transfer.NONE, status_text="")
            for s in uploading[: len(skill_ids)]
        ],
    )
    return Proposal(
        EventKind.SYNC_CONFIRMED,
        agent,
        f"{agent} stored {_ids(uploading[: len(skill_ids)])}",
        Change(put_skills=puts),
    )


def plan_decline_sync(
    state: MissionState, agent: str, skill_ids: Sequence[str], reason: str
) -> Proposal:
    """The robot refused these uploads (or cannot be reached): back to the blueprint."""
    uploading = state.pending(agent, Transfer.UPLOADING)
    _require_run(uploading, skill_ids, agent, "uploads", from_front=False)
    declined = uploading[len(uploading) - len(skill_ids) :]
    text = reason.strip() or "declined by the robot"
    puts = _placed(
        state, [skill_with(s, transfer=Transfer.NONE, status_text=text) for s in declined]
    )
    return Proposal(
        EventKind.SYNC_DECLINED,
        agent,
        f"{agent} did not take {_ids(declined)}: {text}",
        Change(put_skills=puts),
    )


def plan_cancel_uploads(state: MissionState, agent: str, from_id: str | None = None) -> Proposal:
    """Give up on unanswered uploads: the skills return to the editable blueprint now.

    With ``from_id`` among them, only it and the later ones do (the synchronized section
    stays a prefix); otherwise all of them. The robot is told to drop them (see commands),
    in case it got them after all; while they still wait to leave, they never will.
    """
    uploading = state.pending(agent, Transfer.UPLOADING)
    if not uploading:
        raise RuleViolation(f"no upload to {agent} awaits an answer")
    ids = [skill.id for skill in uploading]
    if from_id in ids:
        uploading = uploading[ids.index(from_id) :]
    text = "upload cancelled by the operator"
    puts = _placed(
        state, [skill_with(s, transfer=Transfer.NONE, status_text=text) for s in uploading]
    )
    return Proposal(
        EventKind.UPLOAD_CANCELLED,
        agent,
        f"cancelled the upload of {_ids(uploading)} to {agent}",
        Change(put_skills=puts),
    )


def plan_take_back(state: MissionState, agent: str, from_id: str | None) -> Proposal:
    """Take back ``from_id`` (None: all that may come back) and every later sent skill.

    The operator's *Take back* (the ``unsynchronize`` service), decided by
    :func:`~.legality.take_back_refusal`, the rule the GUIs enable it by: with an upload
    awaiting the robot's answer it cancels the upload (:func:`plan_cancel_uploads`),
    otherwise it asks the robot to give the skills back (:func:`plan_request_unsync`).
    """
    view = TaskView.live(state, agent)
    index = None
    if from_id:
        agent_of, index = state.locate(from_id)
        if agent_of != agent or index >= view.editable_start:
            raise RuleViolation(f"skill '{from_id}' is not in {agent}'s synchronized section")
    refusal = take_back_refusal(view, index)
    if refusal is not None:
        raise RuleViolation(refusal)
    if view.uploading:
        return plan_cancel_uploads(state, agent, from_id)
    return plan_request_unsync(state, agent, from_id)


def take_back_command(state: MissionState, agent: str) -> CommandKind | None:
    """The new work a take-back on ``agent`` gives the robot link now (for the bound of
    :func:`~.waiting.room_refusal`): an UNSYNC request, or None when it cancels an
    unanswered upload (that withdraws waiting work, or cleans up after it, and so is
    never refused for lack of room)."""
    cancels = agent in state.agents and state.pending(agent, Transfer.UPLOADING)
    return None if cancels else CommandKind.UNSYNC


def plan_request_unsync(state: MissionState, agent: str, from_id: str | None) -> Proposal:
    """Ask the robot to give back ``from_id`` and every later synchronized skill."""
    view = TaskView.live(state, agent)
    synced = view.synced
    index = None
    if from_id:
        agent_of, index = state.locate(from_id)
        if agent_of != agent or index >= len(synced):
            raise RuleViolation(f"skill '{from_id}' is not in {agent}'s synchronized section")
    refusal = take_back_refusal(view, index)
    if refusal is not None or view.uploading:
        raise RuleViolation(refusal or f"an upload to {agent} awaits the robot's answer")
    start = unsync_start(view) if index is None else index
    pulled = synced[start:]
    puts = tuple(
        PlacedSkill(start + offset, skill_with(skill, transfer=Transfer.REMOVING))
        for offset, skill in enumerate(pulled)
    )
    return Proposal(
        EventKind.UNSYNC_REQUESTED,
        agent,
        f"asking {agent} to give back {_ids(pulled)}",
        Change(put_skills=puts),
    )


def plan_confirm_unsync(state: MissionState, agent: str, removed_ids: Sequence[str]) -> Proposal:
    """The robot removed ``removed_ids``; they return to the blueprint, the rest stay."""
    removing = state.pending(agent, Transfer.REMOVING)
    if not removing:
        raise RuleViolation(f"no unsynchronize on {agent} awaits an answer")
    _require_run(removing, removed_ids, agent, "removals", from_front=False, allow_empty=True)
    kept = removing[: len(removing) - len(removed_ids)]
    removed = removing[len(kept) :]
    updated = [skill_with(s, transfer=Transfer.NONE) for s in kept]
    updated += [
        skill_with(s, status=S.IDLE, transfer=Transfer.NONE, status_text="") for s in removed
    ]
    summary = f"{agent} gave back {_ids(removed) or 'nothing'}"
    if kept:
        summary += f"; kept {_ids(kept)}, which had started"
    return Proposal(
        EventKind.UNSYNC_CONFIRMED,
        agent,
        summary,
        Change(put_skills=_placed(state, updated)),
    )


def plan_report(
    state: MissionState,
    skill_id: str,
    status: SkillStatus,
    attempt: int | None = None,
    text: str = "",
    stamp: float = 0.0,
    started: float = 0.0,
    finished: float = 0.0,
) -> Proposal:
    """Apply a robot's status report after checking it is legal and in task order.

    ``started`` and ``finished`` are the robot's own times for the skill (0 if it
    gave none); without them the report's ``stamp`` stands in.
    """
    _check_report_fields(status, attempt, text, stamp)
    for value in (started, finished):
        _check_report_fields(status, attempt, text, value)
    text = clip_status_text(text)  # a robot's sentence is kept, made one clean short line
    stamp = float(stamp)
    skill = state.skill(skill_id)
    agent, index = state.locate(skill_id)
    if skill.status is S.IDLE:
        raise RuleViolation(f"skill '{skill_id}' is not synchronized; the report is refused")
    allowed = REPORTABLE.get(skill.status, frozenset())
    if status not in allowed:
        raise RuleViolation(
            f"skill '{skill_id}' cannot go from {skill.status.name} to {status.name}"
        )
    new_attempt = skill.attempt if attempt is None else attempt
    if new_attempt < skill.attempt:
        raise RuleViolation(f"skill '{skill_id}' is at attempt {skill.attempt}, not {new_attempt}")
    if status is skill.status and new_attempt == skill.attempt and text == skill.status_text:
        raise RuleViolation(f"the report for skill '{skill_id}' changes nothing")
    if status is not S.IDLE_SYNCHRONIZED:
        _require_turn(state, agent, index, skill_id)
    began = float(started) or skill.started or (stamp if status.has_started else 0.0)
    new = replace(
        skill,
        status=status,
        attempt=new_attempt,
        status_text=text,
        transfer=Transfer.NONE,
        started=0.0 if status is S.IDLE_SYNCHRONIZED else began,
        finished=(float(finished) or stamp) if status.is_final else 0.0,
    )
    return Proposal(
        EventKind.STATUS_CHANGED,
        agent,
        f"'{skill_id}' on {agent}: {skill.status.name} -> {status.name}"
        + (f" ({text})" if text else ""),
        Change(put_skills=(PlacedSkill(index, new),)),
    )


def _check_report_fields(status: object, attempt: object, text: object, stamp: object) -> None:
    """Refuse report fields the mission could not hold (or save and load again)."""
    if not isinstance(status, SkillStatus):
        raise InvalidRequest(f"{status!r} is not a skill status")
    if attempt is not None and (
        isinstance(attempt, bool) or not isinstance(attempt, int) or attempt < 1
    ):
        raise InvalidRequest(
            f"an attempt must be a whole number of at least 1, got {excerpt(attempt)}"
        )
    if not isinstance(text, str):
        raise InvalidRequest(f"a status text must be text, got {excerpt(text)}")
    if (
        isinstance(stamp, bool)
        or not isinstance(stamp, (int, float))
        or not math.isfinite(stamp)
        or stamp < 0
    ):
        raise InvalidRequest(f"a report stamp must be a finite time >= 0, got {stamp!r}")


def plan_stop(state: MissionState, agent: str) -> Proposal:
    """The active skill of ``agent`` goes back to IDLE_SYNCHRONIZED (restarts next time)."""
    for index, skill in enumerate(state.task(agent)):
        if skill.status.is_active:
            new = skill_with(skill, status=S.IDLE_SYNCHRONIZED, status_text="stopped", started=0.0)
            return Proposal(
                EventKind.SKILL_STOPPED,
                agent,
                f"'{skill.id}' on {agent} stopped",
                Change(put_skills=(PlacedSkill(index, new),)),
            )
    raise RuleViolation(f"{agent} has no running, paused or waiting skill to stop")


def plan_retry(state: MissionState, skill_id: str, new_id: str) -> Proposal:
    """A fresh synchronized instance of a failed skill, right after it (attempt + 1).

    A barrier member that failed before its barrier released hands its place to the
    fresh instance (see :func:`~rosmc_server.core.rules.barriers.after_retry`).
    """
    failed = _unresolved_failure(state, skill_id, "retried")
    agent, index = state.locate(skill_id)
    fresh = replace(
        failed,
        id=new_id,
        status=S.IDLE_SYNCHRONIZED,
        attempt=failed.attempt + 1,
        status_text="",
        started=0.0,
        finished=0.0,
    )
    resolved = replace(failed, resolution=Resolution.RETRIED)
    barrier, said = after_retry(state, skill_id, new_id)
    return Proposal(
        EventKind.SKILL_RETRIED,
        agent,
        f"'{skill_id}' on {agent} retried as '{new_id}' (attempt {fresh.attempt})"
        + (f"; {said}" if said else ""),
        replace(barrier, put_skills=(PlacedSkill(index, resolved), PlacedSkill(index + 1, fresh))),
    )


def plan_skip(state: MissionState, skill_id: str) -> Proposal:
    """Leave a failed skill behind; the robot goes on with the next one.

    A barrier member that failed before its barrier released leaves the barrier, so its
    partners do not wait for ever (see :func:`~rosmc_server.core.rules.barriers.after_skip`).
    """
    failed = _unresolved_failure(state, skill_id, "skipped")
    agent, index = state.locate(skill_id)
    barrier, said = after_skip(state, skill_id)
    return Proposal(
        EventKind.SKILL_SKIPPED,
        agent,
        f"failed '{skill_id}' on {agent} skipped" + (f"; {said}" if said else ""),
        replace(
            barrier,
            put_skills=(PlacedSkill(index, replace(failed, resolution=Resolution.SKIPPED)),),
        ),
    )


def _unresolved_failure(state: MissionState, skill_id: str, verb: str) -> SkillInstance:
    skill = state.skill(skill_id)
    refusal = failure_refusal(skill, verb)
    if refusal is not None:
        raise RuleViolation(refusal)
    return skill


def _require_turn(state: MissionState, agent: str, index: int, skill_id: str) -> None:
    """Only the first unsettled synchronized skill of a robot may run or finish."""
    for earlier in state.task(agent)[:index]:
        if not earlier.is_settled:
            raise RuleViolation(
                f"skill '{skill_id}' cannot progress before '{earlier.id}' "
                f"({earlier.status.name}) on {agent} is done"
            )


def _require_run(
    pending: Sequence[SkillInstance],
    skill_ids: Sequence[str],
    agent: str,
    what: str,
    from_front: bool,
    allow_empty: bool = False,
) -> None:
    """Check ``skill_ids`` are the first (or last) of the pending skills, in order."""
    if not skill_ids and not allow_empty:
        raise InvalidRequest(f"the answer about {agent}'s {what} names no skills")
    ids = [skill.id for skill in pending]
    expected = ids[: len(skill_ids)] if from_front else ids[len(ids) - len(skill_ids) :]
    if len(skill_ids) > len(ids) or list(skill_ids) != expected:
        end = "first" if from_front else "last"
        raise RuleViolation(
            f"{', '.join(skill_ids) or 'nothing'} are not the {end} of {agent}'s pending "
            f"{what} ({', '.join(ids) or 'none'})"
        )


def _placed(state: MissionState, skills: Sequence[SkillInstance]) -> tuple[PlacedSkill, ...]:
    return tuple(PlacedSkill(state.locate(skill.id)[1], skill) for skill in skills)


def _ids(skills: Sequence[SkillInstance]) -> str:
    return ", ".join(skill.id for skill in skills)
