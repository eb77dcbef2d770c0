"""Which robots' columns the task panel shows: a filter by name and by how the robot is.

With a large team (20 robots) the operator narrows the task panel to the robots that need
attention: those whose names match a text (``drone`` or ``rover_1, rover_2``), minus the
robots unticked in the robot list, and optionally only the robots with an unresolved
failure, with something waiting (at a barrier, or commands waiting for contact) or out of
contact. No Qt here: :func:`visible_agents` is a plain function of the mission view.
"""

from __future__ import annotations

import re
from collections.abc import Iterable
from dataclasses import dataclass, field, replace
from enum import Enum

from rosmc_server.core import SkillStatus

from .mission_view import MissionView
from .presentation import is_alarm


class StatusFilter(Enum):
    """Which robots the status filter lets through."""

    ALL = "all"
    FAILED = "failed"
    WAITING = "waiting"
    OUT_OF_CONTACT = "out_of_contact"

    @property
    def label(self) -> str:
        """The button text."""
        return {
            StatusFilter.ALL: "All",
            StatusFilter.FAILED: "Failed",
            StatusFilter.WAITING: "Waiting",
            StatusFilter.OUT_OF_CONTACT: "Out of contact",
        }[self]

    @property
    def tip(self) -> str:
        """What the button shows, in a sentence."""
        return {
            StatusFilter.ALL: "Show every robot that matches the name filter.",
            StatusFilter.FAILED: "Show only robots with a failure nobody has retried or skipped.",
            StatusFilter.WAITING: "Show only robots waiting at a barrier or waiting for contact.",
            StatusFilter.OUT_OF_CONTACT: "Show only robots the ground cannot hear.",
        }[self]


@dataclass(frozen=True)
class TeamFilter:
    """The operator's choice of robots to show.

    ``text``: names or parts of names, separated by commas or spaces (any one matching is
    enough; empty matches every robot). ``hidden``: robots unticked in the robot list.
    ``status``: which robots the status filter lets through.
    """

    text: str = ""
    hidden: frozenset[str] = field(default_factory=frozenset)
    status: StatusFilter = StatusFilter.ALL

    @property
    def active(self) -> bool:
        """Some robot may be hidden by this filter."""
        return bool(self.words or self.hidden) or self.status is not StatusFilter.ALL

    @property
    def words(self) -> list[str]:
        """The text's words, lower case."""
        return [word for word in re.split(r"[,\s]+", self.text.lower()) if word]

    def with_text(self, text: str) -> TeamFilter:
        """This filter with another name text."""
        return replace(self, text=text)

    def with_status(self, status: StatusFilter) -> TeamFilter:
        """This filter with another status choice."""
        return replace(self, status=status)

    def with_shown(self, agent: str, shown: bool) -> TeamFilter:
        """This filter with ``agent`` ticked (shown) or unticked in the robot list."""
        hidden = self.hidden - {agent} if shown else self.hidden | {agent}
        return replace(self, hidden=frozenset(hidden))

    def name_matches(self, agent: str) -> bool:
        """``agent`` passes the name part of the filter (text and robot list)."""
        if agent in self.hidden:
            return False
        words = self.words
        return not words or any(word in agent.lower() for word in words)


def robot_states(view: MissionView, agent: str) -> set[StatusFilter]:
    """The status filters ``agent``'s robot passes now (always ``ALL``)."""
    states = {StatusFilter.ALL}
    skills = view.view(agent).skills
    if any(is_alarm(skill) for skill in skills):
        states.add(StatusFilter.FAILED)
    status = view.statuses.get(agent)
    waiting_for_contact = status is not None and status.commands_waiting > 0
    if waiting_for_contact or any(s.status is SkillStatus.SYNCWAITING for s in skills):
        states.add(StatusFilter.WAITING)
    if view.out_of_contact(agent):
        states.add(StatusFilter.OUT_OF_CONTACT)
    return states


def visible_agents(view: MissionView, agents: Iterable[str], chosen: TeamFilter) -> list[str]:
    """The robots of ``agents`` (in their order) that ``chosen`` shows."""
    return [
        agent
        for agent in agents
        if chosen.name_matches(agent)
        and (chosen.status is StatusFilter.ALL or chosen.status in robot_states(view, agent))
    ]
