"""A robot holding after its lost-link policy acted: it starts no new work until resumed.

When a robot's lost-link policy acts (hold, or return to where it last had a link, then
hold) the executor pauses itself, and its policy line ends "…; holding" or says "held after
N s without ground contact" (the words of ``rosmc_server/executor/core/lost_link.py``).
Work sent to it meanwhile waits on board, and the partners of its barriers wait for it,
until the operator presses Resume. :func:`lost_link_hold` finds such a robot in the view
and :class:`Hold` says it in the operator's words. No Qt here.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass

from rosmc_server.core import SkillStatus
from rosmc_server.core.model.control import ExecutorState
from rosmc_server.core.robots.link import LinkStatus

from .mission_view import MissionView

# How the executor's lost-link note says that the robot holds (see lost_link.py).
HOLD_MARKS = ("; holding", "held after")


@dataclass(frozen=True)
class Hold:
    """A robot holding after its lost-link policy acted.

    Attributes:
        agent: The robot.
        link_back: The ground hears it again (a Resume reaches it at once).
        partners: Robots with a barrier member that waits for this robot, in order.
    """

    agent: str
    link_back: bool
    partners: tuple[str, ...]

    def sentence(self) -> str:
        """What the robot's header and the warnings say, ending with what frees it."""
        agent = self.agent
        when = "after its link came back" if self.link_back else "out of contact"
        text = f"{agent} is holding {when}: it will not start new work"
        if self.partners:
            text += f"; its barrier partners {', '.join(self.partners)} wait for it"
        if self.link_back:
            return f"{text}. Press Resume {agent}."
        return f"{text}. Resume {agent} goes out when it is heard again."

    def sending_warning(self) -> str:
        """The warning in the question before work is sent to the robot."""
        return (
            f"{self.agent} is holding after its lost-link policy acted: what you send waits "
            f"on board until you press Resume {self.agent}."
        )


def lost_link_hold(view: MissionView, agent: str) -> Hold | None:
    """``agent``'s hold, or None when it is not holding after its lost-link policy."""
    status = view.statuses.get(agent)
    if status is None or status.executor is not ExecutorState.PAUSED:
        return None
    if not any(mark in status.policy for mark in HOLD_MARKS):
        return None
    return Hold(agent, status.link is LinkStatus.UP, barrier_partners(view, agent))


def barrier_partners(view: MissionView, agent: str) -> tuple[str, ...]:
    """Robots whose barrier member waits for a member of ``agent`` that has not run yet."""
    partners: dict[str, None] = {}
    for barrier in view.barriers:
        members = view.skills(barrier.skill_ids)
        own = [s for s in members if s.agent == agent]
        if not own or any(s.status.is_final or s.status is SkillStatus.RUNNING for s in own):
            continue  # this robot's member already ran (or runs): nobody waits for it
        for skill in members:
            if skill.agent != agent and not skill.status.is_final:
                partners[skill.agent] = None
    return tuple(partners)


def holds(view: MissionView) -> list[Hold]:
    """Every robot holding after its lost-link policy acted."""
    return [hold for agent in view.statuses if (hold := lost_link_hold(view, agent))]


def hold_warnings(view: MissionView, agents: Iterable[str]) -> list[str]:
    """The warnings for sending work to ``agents``: those holding will not start it."""
    return [hold.sending_warning() for a in agents if (hold := lost_link_hold(view, a))]
