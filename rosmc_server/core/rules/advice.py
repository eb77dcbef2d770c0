"""What an operator should hear with an accepted request: nothing is wrong, but beware.

A request can be legal and still leave the team waiting: synchronizing a skill whose barrier
partners are still in another robot's blueprint makes that robot wait at the barrier until
someone synchronizes the partners, and if both robots then leave coverage nobody can. These
functions find such cases; the server words them as a note on the reply and in the robots'
status.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from typing import Protocol

from ..model.model import Barrier, SkillInstance, SkillStatus
from ..model.state import MissionState


class Members(Protocol):
    """What the barrier advice reads of a mission: the server's state (through
    :class:`~.legality.StatePicture`) or a GUI's copy of it."""

    def skills(self, skill_ids: Sequence[str]) -> list[SkillInstance]:
        """The skills with these ids that exist."""


@dataclass(frozen=True)
class StrandedBarrier:
    """A barrier some of whose members are on their robots (or being sent) and not yet
    past it, while others are still in a blueprint: those robots would wait at it for ever
    unless the planned members are sent too."""

    barrier: Barrier
    going: tuple[SkillInstance, ...]  # synchronized, uploading or being sent, not finished
    planned: tuple[SkillInstance, ...]  # editable blueprint members, not being sent


def stranded_barriers(
    mission: Members, barriers: Iterable[Barrier], sending: Iterable[str] = ()
) -> list[StrandedBarrier]:
    """The ``barriers`` that would strand a robot, if the skills ``sending`` were sent too.

    The one rule of the barrier warnings: the command GUI's standing warning and its
    question before a send pass every barrier; the server's note on an upload passes only
    the barriers of the skills it uploads (so it costs the change, not the mission). A
    member is *planned* while it is editable (:attr:`SkillInstance.is_editable`: in the
    blueprint, not being uploaded) and not in ``sending``.
    """
    sending_ids = set(sending)
    found = []
    for barrier in barriers:
        members = mission.skills(barrier.skill_ids)
        planned = tuple(s for s in members if s.is_editable and s.id not in sending_ids)
        going = tuple(s for s in members if s not in planned and not s.status.is_final)
        if going and planned:
            found.append(StrandedBarrier(barrier, going, planned))
    return found


@dataclass(frozen=True)
class UnsyncedPartner:
    """A barrier partner of a synchronized skill that is still in its robot's blueprint."""

    barrier: Barrier
    skill: SkillInstance  # the synchronized (or uploading) member
    partner: SkillInstance  # the member still in the blueprint

    def sentence(self) -> str:
        """One sentence for the operator."""
        label = f" '{self.partner.label}'" if self.partner.label else ""
        return (
            f"barrier {self.barrier.id} also waits on {self.partner.agent}'s "
            f"{self.partner.skill}{label} ({self.partner.id}), which is not synchronized"
        )


class _StateMembers:
    def __init__(self, state: MissionState) -> None:
        self._state = state

    def skills(self, skill_ids: Sequence[str]) -> list[SkillInstance]:
        return [self._state.skill(i) for i in skill_ids if self._state.has_skill(i)]


def unsynced_partners(state: MissionState, skill_ids: Iterable[str]) -> list[UnsyncedPartner]:
    """Barrier partners, still in a blueprint, of the skills ``skill_ids`` (by
    :func:`stranded_barriers`, over their barriers only)."""
    wanted = list(skill_ids)
    barriers = {b.id: b for i in wanted if (b := state.barrier_of(i)) is not None}
    found = []
    for stranded in stranded_barriers(_StateMembers(state), barriers.values()):
        going = {s.id: s for s in stranded.going}
        for skill_id in wanted:
            if skill_id in going:
                found += [
                    UnsyncedPartner(stranded.barrier, going[skill_id], p) for p in stranded.planned
                ]
    return found


def waiting_on_unsynced(state: MissionState, agent: str) -> list[str]:
    """Agents whose unsynchronized skills ``agent``'s next barrier waits on.

    The next barrier is that of the first synchronized skill of ``agent`` that has not
    finished; empty if it has none or every partner is synchronized.
    """
    for skill in state.task(agent)[: state.sections(agent).synced_end]:
        if skill.status in (SkillStatus.SUCCESS, SkillStatus.FAILURE):
            continue
        partners = unsynced_partners(state, [skill.id])
        return sorted({p.partner.agent for p in partners})
    return []
