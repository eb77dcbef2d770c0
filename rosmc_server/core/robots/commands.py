"""Which robot-link commands each accepted mission change requires.

The mission server turns events into commands with :func:`commands_for_event`;
the robot executor applies them. Both sides compute the queue hash from the
same ordered ids (:func:`synced_ids`), so a disagreement shows at once.
"""

from __future__ import annotations

import enum
from dataclasses import dataclass

from ..model.changes import EventKind, MissionEvent
from ..model.model import Barrier, SkillInstance
from ..model.state import MissionState
from ..skills.library import Library
from ..skills.policy import options_argument


class CommandKind(enum.IntEnum):
    """Robot-link command types (numbers match ``rosmc/RobotCommand``)."""

    UPLOAD = 0
    UNSYNC = 1
    START = 2
    PAUSE = 3
    RESUME = 4
    STOP = 5
    RETRY = 6
    SKIP = 7
    BARRIERS = 8
    SET_OPTIONS = 9
    SYNC_STATE = 10


@dataclass(frozen=True)
class CommandSpec:
    """A command for one agent's robot, before the link numbers it.

    ``barriers``, where given (UPLOAD, BARRIERS, SYNC_STATE), is the complete
    set of barriers of the skills the robot holds or is being sent; it replaces
    the robot's set.
    """

    agent: str
    kind: CommandKind
    skills: tuple[SkillInstance, ...] = ()
    skill_ids: tuple[str, ...] = ()
    barriers: tuple[Barrier, ...] = ()
    argument: str = ""


def synced_ids(state: MissionState, agent: str) -> list[str]:
    """Ids of the skills the robot holds, in order: the synchronized section."""
    task = state.task(agent)
    return [skill.id for skill in task[: state.sections(agent).synced_end]]


def barriers_for(state: MissionState, skill_ids: set[str]) -> tuple[Barrier, ...]:
    """Barriers that have a member among ``skill_ids``."""
    return tuple(b for b in state.barriers if skill_ids.intersection(b.skill_ids))


def queued_barriers(state: MissionState, agent: str) -> tuple[Barrier, ...]:
    """Barriers of the skills ``agent``'s robot holds or is being sent."""
    held = state.task(agent)[: state.sections(agent).editable_start]  # synchronized, uploading
    return barriers_for(state, {s.id for s in held})


def commands_for_event(event: MissionEvent, state: MissionState) -> list[CommandSpec]:
    """The commands an event (already applied to ``state``) requires."""
    change = event.change
    kind = event.kind
    if kind is EventKind.SYNC_REQUESTED:  # one robot's upload, or a team's (one per robot)
        by_agent: dict[str, list[SkillInstance]] = {}
        for placed in change.put_skills:
            by_agent.setdefault(placed.skill.agent, []).append(placed.skill)
        return [
            CommandSpec(
                agent, CommandKind.UPLOAD, tuple(skills), barriers=queued_barriers(state, agent)
            )
            for agent, skills in by_agent.items()
        ]
    if kind in (EventKind.UNSYNC_REQUESTED, EventKind.UPLOAD_CANCELLED):
        # A cancelled upload may have reached the robot after all: have it dropped.
        ids = tuple(placed.skill.id for placed in change.put_skills)
        return [CommandSpec(event.agent, CommandKind.UNSYNC, skill_ids=ids)]
    # New barrier sets go first: a retried robot must know the barrier its fresh
    # instance joined before the RETRY lets it start that instance.
    barrier_sets = (
        [
            CommandSpec(agent, CommandKind.BARRIERS, barriers=queued_barriers(state, agent))
            for agent in state.agents
            if synced_ids(state, agent)
        ]
        if change.put_barriers or change.removed_barrier_ids
        else []
    )
    if kind is EventKind.SKILL_RETRIED:
        failed, fresh = change.put_skills[0].skill, change.put_skills[1].skill
        return [*barrier_sets, CommandSpec(event.agent, CommandKind.RETRY, (fresh,), (failed.id,))]
    if kind is EventKind.SKILL_SKIPPED:
        failed_id = change.put_skills[0].skill.id
        return [*barrier_sets, CommandSpec(event.agent, CommandKind.SKIP, skill_ids=(failed_id,))]
    return barrier_sets


def repair_command(state: MissionState, agent: str) -> CommandSpec:
    """Replace the robot's queue with the ground's synchronized section."""
    task = state.task(agent)
    skills = tuple(task[: state.sections(agent).synced_end])
    return CommandSpec(
        agent, CommandKind.SYNC_STATE, skills, barriers=queued_barriers(state, agent)
    )


def default_policy_commands(library: Library) -> list[CommandSpec]:
    """SET_OPTIONS commands that give each robot its model's default lost-link policy.

    The server queues them at start, so each robot gets its default when it first
    links; a robot whose operator chose a policy keeps that one.
    """
    return [
        CommandSpec(agent, CommandKind.SET_OPTIONS, argument=options_argument(policy, True))
        for agent in library.dynamic_agents
        if (policy := library.default_policy(agent)) is not None
    ]
