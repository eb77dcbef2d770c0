"""Replacing the whole mission (a load, a new mission): what a loaded file keeps, and
the check that no robot holds a skill. Part of :class:`~.mission.Mission`.

Both look at every skill (20,000 in a large mission), so each first asks about the few
distinct (status, transfer) pairs of a task, read off in one pass in C, and walks the
skills one by one only where some skill must change or be named.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from dataclasses import replace
from operator import attrgetter

from ..errors import RuleViolation
from ..model.model import SkillInstance, SkillStatus, Transfer

_STATE = attrgetter("status", "transfer")
# What a robot holds: a synchronized skill not finished (waiting, running or paused too).
_HELD_BY_ROBOT = frozenset({SkillStatus.IDLE_SYNCHRONIZED}) | frozenset(
    status for status in SkillStatus if status.is_active
)


def loaded_tasks(tasks: Mapping[str, list[SkillInstance]]) -> dict[str, list[SkillInstance]]:
    """The tasks of a loaded file, each skill the file shows as synchronized but
    unfinished back in the blueprint (no robot holds it now); SUCCESS and FAILURE stay
    as logs."""
    return {agent: _loaded(task) for agent, task in tasks.items()}


def _loaded(task: list[SkillInstance]) -> list[SkillInstance]:
    if all(_kept(status, transfer) for status, transfer in set(map(_STATE, task))):
        return list(task)
    idle, none = SkillStatus.IDLE, Transfer.NONE
    return [
        s
        if _kept(s.status, s.transfer)
        else replace(s, status=idle, transfer=none, status_text="", started=0.0)
        for s in task
    ]


def _kept(status: SkillStatus, transfer: Transfer) -> bool:
    return (status is SkillStatus.IDLE and transfer is Transfer.NONE) or status.is_final


def robots_idle_refusal(tasks: Iterable[list[SkillInstance]], action: str) -> str | None:
    """Why the mission cannot be replaced (``action``: "load a mission", ...): the first
    skill a robot holds (synchronized and not finished, or in transfer); None if none."""
    for task in tasks:
        states = set(map(_STATE, task))
        if all(s not in _HELD_BY_ROBOT and t is Transfer.NONE for s, t in states):
            continue
        for skill in task:
            if skill.status in _HELD_BY_ROBOT or skill.transfer is not Transfer.NONE:
                return (
                    f"cannot {action} while {skill.agent} holds unfinished skill '{skill.id}'; "
                    "unsynchronize or stop it first"
                )
    return None


def require_robots_idle(tasks: Iterable[list[SkillInstance]], action: str) -> None:
    """RuleViolation with :func:`robots_idle_refusal`'s sentence, if it has one."""
    refusal = robots_idle_refusal(tasks, action)
    if refusal is not None:
        raise RuleViolation(refusal)
