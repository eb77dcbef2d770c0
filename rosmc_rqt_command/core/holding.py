"""A robot holding after its lost-link policy acted, and every barrier wait, for the GUI.

When a robot's lost-link policy acts (hold, or return to where it last had a link, then
hold) the robot reports why it holds (``AgentStatus.hold``, a
:class:`~rosmc_server.core.model.control.HoldCause`). Work sent to it meanwhile waits on board,
and the partners of its barriers wait for it, until the operator presses Resume.
:func:`lost_link_hold` finds such a robot in the view and :class:`Hold` says it in the
operator's words (:mod:`rosmc_server.core.views.holding`, shared with rviz and ``rosmc``);
:func:`barrier_wait` says what a robot waiting at a barrier waits for, and since how long.
No Qt here.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass

from rosmc_server.core import SkillStatus
from rosmc_server.core.model.control import HoldCause
from rosmc_server.core.robots.link import LinkStatus
from rosmc_server.core.views import holding as words

from .mission_view import MissionView


@dataclass(frozen=True)
class Hold:
    """A robot holding after its lost-link policy acted.

    Attributes:
        agent: The robot.
        link_back: The ground hears it again (a Resume reaches it at once).
        partners: Robots with a barrier member that waits for this robot, in order.
        cause: Why (and so where) it holds.
    """

    agent: str
    link_back: bool
    partners: tuple[str, ...]
    cause: HoldCause = HoldCause.LOST_LINK

    def sentence(self) -> str:
        """What the robot's header and the warnings say; the Resume button follows it."""
        return words.hold_sentence(self.agent, self.cause, self.partners, self.link_back)

    def sending_warning(self) -> str:
        """The warning in the question before work is sent to the robot."""
        return (
            f"{self.agent} is holding after its lost-link policy acted: what you send waits "
            f"on board until you press Resume {self.agent}."
        )


def lost_link_hold(view: MissionView, agent: str) -> Hold | None:
    """``agent``'s hold, or None when it is not holding after its lost-link policy."""
    status = view.statuses.get(agent)
    if status is None or status.hold is HoldCause.NONE:
        return None
    partners = barrier_partners(view, agent)
    return Hold(agent, status.link is LinkStatus.UP, partners, status.hold)


def barrier_partners(view: MissionView, agent: str) -> tuple[str, ...]:
    """Robots whose barrier member waits for a member of ``agent`` that has not run yet."""
    return words.barrier_partners(view.barriers, view.skill, agent)


def holds(view: MissionView) -> list[Hold]:
    """Every robot holding after its lost-link policy acted."""
    return [hold for agent in view.statuses if (hold := lost_link_hold(view, agent))]


def hold_warnings(view: MissionView, agents: Iterable[str]) -> list[str]:
    """The warnings for sending work to ``agents``: those holding will not start it."""
    return [hold.sending_warning() for a in agents if (hold := lost_link_hold(view, a))]


def barrier_wait(view: MissionView, agent: str) -> str:
    """``waits for r4 at barrier B2 since 1 min 32 s``; "" if ``agent`` waits at none.

    The names are the partners whose member has not arrived at the barrier (as the
    mission shows it); the age is the robot's own (``AgentStatus.barrier_wait``).
    """
    status = view.statuses.get(agent)
    if status is None or not status.current_skill:
        return ""
    skill = view.skill(status.current_skill)
    barrier = view.barrier_of(status.current_skill)
    if skill is None or barrier is None or skill.status is not SkillStatus.SYNCWAITING:
        return ""
    missing = words.not_arrived(view.skills(barrier.skill_ids), agent)
    name = f"B{view.barrier_number(skill.id)}"
    return f"{agent} {words.wait_sentence(missing, name, status.barrier_wait)}"
