"""Warnings an operator needs before it is too late, computed from the mission view.

* A synchronized barrier member whose partner is still in the blueprint: the robot will
  wait at the barrier for ever unless the partner is sent too.
* A robot about to leave Wi-Fi coverage (weak signal), or out of it, while it still has
  planned work not sent: once out of range, what is sent waits until it is heard again.
  The signal is said in a word; its dBm are in the robot header's tooltip.
* A skill whose parameter the library marks invalid (out of range, wrong type).
* A robot whose radio link dropped forged datagrams (unsigned, wrong key, replayed).

No Qt here.
"""

from __future__ import annotations

import itertools
import time
from collections.abc import Iterable, Sequence

from rosmc_server.core import Library, RosmcError, SkillInstance
from rosmc_server.core.rules.advice import stranded_barriers
from rosmc_server.core.views.vocabulary import counted

from .mission_view import MissionView

WEAK_WIFI_DBM = -75.0  # below this a robot is about to lose the link


def barrier_warnings(view: MissionView, sending: Sequence[SkillInstance] = ()) -> list[str]:
    """Barrier members on a robot (or being sent) whose partners are still planned (the
    core's rule, :func:`~rosmc_server.core.rules.advice.stranded_barriers`, worded here)."""
    out = []
    for stranded in stranded_barriers(view, view.barriers, [s.id for s in sending]):
        robots = ", ".join(s.agent for s in stranded.going)
        missing = ", ".join(f"{s.agent}'s '{s.label or s.skill}'" for s in stranded.planned)
        out.append(f"{robots} will wait at a barrier for ever unless you also send {missing}.")
    return out


def coverage_warnings(view: MissionView) -> list[str]:
    """Robots with a weak or lost Wi-Fi signal that still have planned work not sent.

    Skills already sent (uploading, or waiting for contact) are not counted: they go out
    by themselves once the robot is heard, and the robot's header says so.
    """
    out = []
    for agent, status in view.statuses.items():
        task = view.view(agent)
        unsent = len(task.skills) - task.editable_start
        if not unsent or status.wifi_signal is None:
            continue
        skills = counted(unsent, "planned skill")
        if not status.in_coverage:
            out.append(
                f"{agent} is out of Wi-Fi range with {skills} not on board; what you send "
                "now waits until it is heard again."
            )
        elif status.wifi_signal < WEAK_WIFI_DBM:
            out.append(
                f"{agent} is about to leave Wi-Fi range (weak signal) "
                f"with {skills} not on board; send them now."
            )
    return out


def radio_warnings(view: MissionView) -> list[str]:
    """Robots whose radio link dropped forged datagrams: someone without the key is talking."""
    return [
        f"{agent}: {status.radio_text} (someone without the deployment's key is sending)."
        for agent, status in view.statuses.items()
        if status.radio_dropped
    ]


class ParameterChecker:
    """Finds skills with a parameter the library refuses, checking only what changed.

    :meth:`note` marks the skills an update touched (all of them after a new mission or
    library); :meth:`warnings` checks marked skills for at most ``budget`` seconds per
    call, so a 10,000-skill mission never blocks the window: the rest waits for the
    next call (:attr:`incomplete`).
    """

    def __init__(self, budget: float = 0.01) -> None:
        self._budget = budget
        self._dirty: dict[str, None] = {}  # ordered set of skill ids to check
        self._all = True  # everything needs checking (start, new mission, new library)
        self._problems: dict[str, str] = {}

    @property
    def incomplete(self) -> bool:
        """Skills are left to check (call :meth:`warnings` again soon)."""
        return self._all or bool(self._dirty)

    def note(self, skill_ids: Iterable[str] | None) -> None:
        """These skills changed (None: every skill, e.g. a new mission or library)."""
        if skill_ids is None:
            self._all = True
            self._dirty = {}
        elif not self._all:
            self._dirty.update(dict.fromkeys(skill_ids))

    def warnings(self, view: MissionView) -> list[str]:
        """One sentence per unfinished skill with an invalid parameter."""
        library = view.library
        if library is None:
            return []
        if self._all:
            self._all = False
            self._problems = {}
            self._dirty = {s.id: None for task in view.agents.values() for s in task.skills}
        deadline = time.monotonic() + self._budget
        while self._dirty and time.monotonic() < deadline:
            for skill_id in list(itertools.islice(self._dirty, 10)):
                del self._dirty[skill_id]
                skill = view.skill(skill_id)
                problem = "" if skill is None else _problem(library, skill)
                if problem:
                    self._problems[skill_id] = problem
                else:
                    self._problems.pop(skill_id, None)
        return list(self._problems.values())


def _problem(library: Library, skill: SkillInstance) -> str:
    if skill.status.is_final:
        return ""
    try:
        spec = library.skill(skill.agent, skill.skill)
        for name, value in skill.params.items():
            spec.parameter(name).check(value, skill.skill)
    except RosmcError as error:
        return f"{skill.agent}'s '{skill.label or skill.skill}': {error}."
    return ""
