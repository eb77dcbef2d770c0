"""What an operator should hear with an accepted request: nothing is wrong, but beware.

A request can be legal and still leave the team waiting: synchronizing a skill whose barrier
partners are still in another robot's blueprint makes that robot wait at the barrier until
someone synchronizes the partners, and if both robots then leave coverage nobody can. These
functions find such cases; the server words them as a note on the reply and in the robots'
status.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass

from .model import Barrier, SkillInstance, SkillStatus
from .state import MissionState


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


def unsynced_partners(state: MissionState, skill_ids: Iterable[str]) -> list[UnsyncedPartner]:
    """Barrier partners, still in a blueprint, of the skills ``skill_ids``."""
    found = []
    for skill_id in skill_ids:
        barrier = state.barrier_of(skill_id)
        if barrier is None:
            continue
        skill = state.skill(skill_id)
        for partner_id in barrier.skill_ids:
            partner = state.skill(partner_id)
            if partner_id != skill_id and partner.is_editable:
                found.append(UnsyncedPartner(barrier, skill, partner))
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
