"""Changes to a robot's queue of synchronized skills, as pure functions.

The queue is the ordered list of skills the robot holds. These functions
implement the command semantics the ground relies on (see
:mod:`rosmc_server.core.robots.commands`) and never touch execution state.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, replace

from rosmc_server.core import Resolution, SkillInstance, SkillStatus, Transfer

Checker = Callable[[SkillInstance], str]  # why a skill cannot run here, "" if it can


@dataclass(frozen=True)
class Answer:
    """The new queue and what the robot tells the ground."""

    queue: list[SkillInstance]
    accepted: tuple[str, ...] = ()
    rejected: tuple[str, ...] = ()
    reasons: tuple[str, ...] = ()


def held(skill: SkillInstance) -> SkillInstance:
    """A skill as the robot stores it: synchronized, with no transfer pending."""
    return replace(skill, status=SkillStatus.IDLE_SYNCHRONIZED, transfer=Transfer.NONE)


def upload(
    queue: Sequence[SkillInstance], skills: Sequence[SkillInstance], why_not: Checker
) -> Answer:
    """Append ``skills`` in order; after the first refused one, refuse the rest.

    A skill the robot already holds is accepted unchanged (a repeated upload).
    """
    out = list(queue)
    have = {s.id for s in queue}
    accepted: list[str] = []
    rejected: list[str] = []
    reasons: list[str] = []
    for skill in skills:
        reason = f"follows refused skill '{rejected[0]}'" if rejected else ""
        if not reason and skill.id not in have:
            reason = why_not(skill)
        if reason:
            rejected.append(skill.id)
            reasons.append(reason)
            continue
        if skill.id not in have:
            out.append(held(skill))
        accepted.append(skill.id)
    return Answer(out, tuple(accepted), tuple(rejected), tuple(reasons))


def unsync(queue: Sequence[SkillInstance], skill_ids: Sequence[str], active_id: str) -> Answer:
    """Remove the longest run of not-started skills at the end of ``skill_ids``.

    An id the robot no longer holds counts as removed; the first started one
    (and everything requested before it) is kept.
    """
    index = {s.id: s for s in queue}
    removed: list[str] = []
    for skill_id in reversed(skill_ids):
        skill = index.get(skill_id)
        started = skill is not None and (
            skill.status is not SkillStatus.IDLE_SYNCHRONIZED or skill_id == active_id
        )
        if started:
            break
        removed.insert(0, skill_id)
    gone = set(removed)
    kept = tuple(skill_ids[: len(skill_ids) - len(removed)])
    return Answer(
        [s for s in queue if s.id not in gone],
        tuple(removed),
        kept,
        tuple("it had started" for _ in kept),
    )


def retry(queue: Sequence[SkillInstance], failed_id: str, fresh: SkillInstance) -> Answer:
    """Mark a failure retried and hold its fresh instance right after it."""
    position = next((i for i, s in enumerate(queue) if s.id == failed_id), None)
    if position is None or queue[position].status is not SkillStatus.FAILURE:
        return Answer(list(queue), rejected=(failed_id,), reasons=("nothing to retry",))
    out = list(queue)
    out[position] = replace(out[position], resolution=Resolution.RETRIED)
    if all(s.id != fresh.id for s in out):
        out.insert(position + 1, held(fresh))
    return Answer(out, accepted=(fresh.id,))


def skip(queue: Sequence[SkillInstance], failed_id: str) -> Answer:
    """Mark a failure skipped."""
    position = next((i for i, s in enumerate(queue) if s.id == failed_id), None)
    if position is None or queue[position].status is not SkillStatus.FAILURE:
        return Answer(list(queue), rejected=(failed_id,), reasons=("nothing to skip",))
    out = list(queue)
    out[position] = replace(out[position], resolution=Resolution.SKIPPED)
    return Answer(out, accepted=(failed_id,))


def adopt(
    queue: Sequence[SkillInstance], ground: Sequence[SkillInstance], why_not: Checker
) -> Answer:
    """Make the queue the ground's list, keeping what is under way here (a repair).

    A skill the ground logged as finished stays finished: a robot that lost its
    state must not run again what it has done. Finished skills the ground no
    longer lists (it started a new mission) are dropped; their reports are kept
    apart, until acknowledged.
    """
    mine = {s.id: s for s in queue}
    wanted = {s.id for s in ground}
    out = [s for s in queue if s.id not in wanted and s.status.is_active]
    for skill in ground:
        if skill.id in mine:
            out.append(mine[skill.id])
        elif skill.status.is_final:
            out.append(replace(skill, transfer=Transfer.NONE))
        elif not why_not(skill):
            out.append(held(skill))
    return Answer(out, accepted=tuple(s.id for s in out))


def upcoming(queue: Sequence[SkillInstance]) -> SkillInstance | None:
    """The first skill that is not done for good (SUCCESS, or a retried/skipped FAILURE)."""
    for skill in queue:
        if skill.status is SkillStatus.SUCCESS or skill.resolution is not Resolution.NONE:
            continue
        return skill
    return None


def holding(queue: Sequence[SkillInstance]) -> SkillInstance | None:
    """The unresolved FAILURE the robot holds at, if any."""
    skill = upcoming(queue)
    return skill if skill is not None and skill.status is SkillStatus.FAILURE else None
