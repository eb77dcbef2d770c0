"""A robot holding after its lost-link policy, and the barrier waits, in the operator's words.

A robot whose lost-link policy acted (hold where it was, or return to where it last had a
link, then hold) reports why it holds (:class:`~..model.control.HoldCause`). It starts no new work
and the partners of its barriers wait for it until the operator resumes it: the one action
that frees it. The command GUI, rviz and ``rosmc status`` say it with these words, and say
each barrier wait the same way: whom the robot waits for, where, and since how long
(the words themselves are :mod:`.vocabulary`'s).
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Sequence

from ..model.control import HoldCause
from ..model.model import Barrier, SkillInstance, SkillStatus
from .vocabulary import HOLD_WHERE, age_text

_ARRIVED = frozenset({SkillStatus.SYNCWAITING, SkillStatus.RUNNING})


def hold_sentence(agent: str, cause: HoldCause, partners: Sequence[str], link_back: bool) -> str:
    """``r4 holds at its lost-link return point — its barrier partners r1, r2 wait.``

    Out of contact it adds that a Resume goes out once the robot is heard again.
    """
    text = f"{agent} holds {HOLD_WHERE[cause]}"
    if partners:
        text += f" \u2014 its barrier partners {', '.join(partners)} wait"
    text += "."
    if not link_back:
        text += f" It is out of contact: Resume {agent} goes out once it is heard again."
    return text


def wait_sentence(waits_for: Sequence[str], barrier: str, age: float) -> str:
    """``waits for r4 at barrier B2 since 1 min 32 s`` (no age if ``age`` is negative)."""
    who = ", ".join(waits_for) if waits_for else "its partners' confirmation"
    text = f"waits for {who} at barrier {barrier}"
    return f"{text} since {age_text(age)}" if age >= 0 else text


def not_arrived(members: Iterable[SkillInstance], agent: str) -> tuple[str, ...]:
    """The robots, other than ``agent``, whose member of a barrier has not arrived there.

    ``members`` are the barrier's skills. A member arrived when it waits there or runs (the
    barrier let it go); a paused one left the wait, a finished one will never come.
    """
    return tuple(
        dict.fromkeys(
            s.agent
            for s in members
            if s.agent != agent and s.status not in _ARRIVED and not s.status.is_final
        )
    )


def barrier_partners(
    barriers: Iterable[Barrier],
    find: Callable[[str], SkillInstance | None],
    agent: str,
) -> tuple[str, ...]:
    """Robots with a barrier member that waits for a member of ``agent`` not run yet."""
    partners: dict[str, None] = {}
    for barrier in barriers:
        members = [s for i in barrier.skill_ids if (s := find(i)) is not None]
        own = [s for s in members if s.agent == agent]
        if not own or any(s.status.is_final or s.status is SkillStatus.RUNNING for s in own):
            continue  # this robot's member already ran (or runs): nobody waits for it
        for skill in members:
            if skill.agent != agent and not skill.status.is_final:
                partners[skill.agent] = None
    return tuple(partners)
