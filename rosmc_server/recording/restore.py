"""A past moment of a recording as a new blueprint: ``rosmc restore FILE --at T``.

To re-plan from a moment, what the robots already did stays in the past: skills that
ended (SUCCESS or FAILURE) are dropped, every other skill goes back into its robot's
blueprint as IDLE (first attempt, no status), barriers whose members all remain are kept,
and every task marker is kept.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

from ..core import (
    Barrier,
    MissionContent,
    MissionState,
    Resolution,
    SkillInstance,
    SkillStatus,
    Transfer,
)


@dataclass(frozen=True)
class Restored:
    """The blueprint built from a past mission, and what was left out of it."""

    content: MissionContent
    kept: int  # skills put in the blueprint
    dropped: tuple[str, ...]  # ids of executed skills left out
    barriers_dropped: tuple[str, ...]  # barriers with a member left out


def blueprint_from(state: MissionState) -> Restored:
    """The mission of ``state`` as a blueprint to re-plan from."""
    content = state.content()
    dropped = tuple(skill.id for skill in state.skills() if skill.status.is_final)
    tasks = {
        agent: [_fresh(skill) for skill in task if not skill.status.is_final]
        for agent, task in content.tasks.items()
    }
    kept_ids = {skill.id for task in tasks.values() for skill in task}
    barriers: dict[str, Barrier] = {}
    barriers_dropped = []
    for barrier_id, barrier in content.barriers.items():
        if all(member in kept_ids for member in barrier.skill_ids):
            barriers[barrier_id] = barrier
        else:
            barriers_dropped.append(barrier_id)
    return Restored(
        MissionContent(content.library, tasks, barriers, dict(content.markers)),
        kept=len(kept_ids),
        dropped=dropped,
        barriers_dropped=tuple(barriers_dropped),
    )


def _fresh(skill: SkillInstance) -> SkillInstance:
    """The skill as the operator wrote it: in the blueprint, never run."""
    return replace(
        skill,
        status=SkillStatus.IDLE,
        transfer=Transfer.NONE,
        resolution=Resolution.NONE,
        attempt=1,
        status_text="",
        started=0.0,
        finished=0.0,
    )
