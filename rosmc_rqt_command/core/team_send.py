"""Sending several robots' tasks in one step, and the one question asked before it.

A barrier plan is only safe once every robot in it holds its part: sending the robots one
by one asked one question per robot about partners not sent yet. :func:`plan_team_send`
works out what each robot would get (its whole blueprint, or up to a chosen skill), and
:func:`team_question` words it, with every warning at once, for one dialog. The server
then takes the whole team in one change, or nobody (``synchronize_team``). No Qt here.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

from rosmc_server.core import SkillInstance
from rosmc_server.core.views.vocabulary import counted

from . import alerts
from .holding import hold_warnings
from .mission_view import MissionView


@dataclass(frozen=True)
class TeamSend:
    """What a team send asks for and what each robot would get.

    Attributes:
        uploads: Robot -> last skill to send (None: its whole blueprint), for the server.
        sending: Robot -> the blueprint skills it would get, in order.
    """

    uploads: Mapping[str, str | None]
    sending: Mapping[str, tuple[SkillInstance, ...]]

    @property
    def skills(self) -> list[SkillInstance]:
        """Every skill that would be sent."""
        return [skill for skills in self.sending.values() for skill in skills]

    def lines(self) -> list[str]:
        """One line per robot: how many skills go, and up to which."""
        out = []
        for agent, skills in self.sending.items():
            last = skills[-1]
            how = "its whole task" if self.uploads[agent] is None else "up to"
            out.append(
                f"{agent}: {counted(len(skills), 'skill')}, {how} '{last.label or last.skill}'"
            )
        return out


def plan_team_send(view: MissionView, uploads: Mapping[str, str | None]) -> TeamSend | None:
    """The send of ``uploads`` (robots with nothing to send are left out); None if empty."""
    sending: dict[str, tuple[SkillInstance, ...]] = {}
    kept: dict[str, str | None] = {}
    for agent, upto in uploads.items():
        editable = view.view(agent).editable
        ids = [skill.id for skill in editable]
        end = ids.index(upto) + 1 if upto in ids else len(ids)
        if end:
            sending[agent], kept[agent] = tuple(editable[:end]), upto
    return TeamSend(kept, sending) if sending else None


def whole_team(view: MissionView) -> dict[str, str | None]:
    """Every robot with planned skills, each with its whole blueprint."""
    return {agent: None for agent in view.agents if view.view(agent).editable}


def up_to_selection(view: MissionView, selected: list[SkillInstance]) -> dict[str, str | None]:
    """Each robot of the selection up to its last selected skill."""
    uploads: dict[str, str | None] = {}
    for skill in sorted(selected, key=view.position):
        uploads[skill.agent] = skill.id  # the robot's last selected skill wins
    return {agent: uploads[agent] for agent in view.agents if agent in uploads}


def team_question(view: MissionView, send: TeamSend) -> tuple[str, list[str]]:
    """The question to ask before ``send`` and the warnings it must list."""
    warnings = alerts.barrier_warnings(view, send.skills) + hold_warnings(view, send.sending)
    robots = ", ".join(send.sending)
    if len(send.sending) == 1:
        head = f"Send to {robots}:\n"
    else:
        head = f"Send in one step to {robots} (all of them or none):\n"
    text = head + "\n".join(f"  • {line}" for line in send.lines())
    return text, warnings
