"""Warnings an operator needs before it is too late, computed from the mission view.

* A synchronized barrier member whose partner is still in the blueprint: the robot will
  wait at the barrier for ever unless the partner is sent too.
* A robot about to leave Wi-Fi coverage (weak signal) while it still has planned work
  that is not on board: once out of range it cannot receive it.
* A skill whose parameter the library marks invalid (out of range, wrong type).

No Qt here.
"""

from __future__ import annotations

from collections.abc import Sequence

from rosmc_server.core import RosmcError, SkillInstance, SkillStatus

from .mission_view import MissionView

WEAK_WIFI_DBM = -75.0  # below this a robot is about to lose the link


def barrier_warnings(view: MissionView, sending: Sequence[SkillInstance] = ()) -> list[str]:
    """Barrier members on a robot (or being sent) whose partners are still planned."""
    sending_ids = {skill.id for skill in sending}
    out = []
    for barrier in view.barriers:
        members = view.skills(barrier.skill_ids)
        on_robot = [s for s in members if s.id in sending_ids or s.status is not SkillStatus.IDLE]
        planned = [s for s in members if s.status is SkillStatus.IDLE and s.id not in sending_ids]
        if on_robot and planned and not all(s.status.has_started for s in on_robot):
            robots = ", ".join(s.agent for s in on_robot)
            missing = ", ".join(f"{s.agent}'s '{s.label or s.skill}'" for s in planned)
            out.append(f"{robots} will wait at a barrier for ever unless you also send {missing}.")
    return out


def coverage_warnings(view: MissionView) -> list[str]:
    """Robots with a weak or lost Wi-Fi signal that still have planned work not on board."""
    out = []
    for agent, status in view.statuses.items():
        planned = len(view.view(agent).blueprint)
        if not planned or status.wifi_signal is None:
            continue
        if not status.in_coverage:
            out.append(
                f"{agent} is out of Wi-Fi range; its {planned} planned skills cannot be sent."
            )
        elif status.wifi_signal < WEAK_WIFI_DBM:
            out.append(
                f"{agent} is about to leave Wi-Fi range ({status.wifi_signal:.0f} dBm) "
                f"with {planned} planned skills not on board; send them now."
            )
    return out


class ParameterChecker:
    """Finds skills with a parameter the library refuses; re-checks only changed skills."""

    def __init__(self, budget: int = 500) -> None:
        self._seen: dict[str, tuple[SkillInstance, str]] = {}
        self._budget = budget
        self.incomplete = False  # skills were left for the next call (keeps each call short)

    def warnings(self, view: MissionView) -> list[str]:
        """One sentence per unfinished skill with an invalid parameter."""
        library = view.library
        if library is None:
            return []
        out = []
        seen: dict[str, tuple[SkillInstance, str]] = {}
        checks = 0
        self.incomplete = False
        for task in view.agents.values():
            for skill in task.skills:
                if skill.status.is_final:
                    continue
                cached = self._seen.get(skill.id)
                problem = cached[1] if cached is not None and cached[0] is skill else ""
                if cached is None or cached[0] is not skill:
                    checks += 1
                    if checks > self._budget:
                        self.incomplete = True
                        continue
                    try:
                        spec = library.skill(skill.agent, skill.skill)
                        for name, value in skill.params.items():
                            spec.parameter(name).check(value, skill.skill)
                    except RosmcError as error:
                        problem = f"{skill.agent}'s '{skill.label or skill.skill}': {error}."
                seen[skill.id] = (skill, problem)
                if problem:
                    out.append(problem)
        self._seen = seen
        return out
