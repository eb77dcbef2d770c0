"""Synchronizing several robots at once: one change, one revision, all or nothing.

A barrier plan needs every robot in it synchronized before any of them can go past the
barrier. Sending the robots one by one leaves the team half-sent between the requests (and
a refusal for the last robot leaves the others waiting at the barrier); here the whole
team's uploads are checked first and committed as one ``SYNC_REQUESTED`` event whose
skills belong to several agents.
"""

from __future__ import annotations

from collections.abc import Mapping

from ..errors import RuleViolation
from ..model.changes import Change, EventKind, PlacedSkill, Proposal
from ..model.state import MissionState
from .execution import plan_synchronize

# Each robot and the last skill of its blueprint to send (None: the whole blueprint).
TeamUploads = Mapping[str, "str | None"]


def robots_with_blueprints(state: MissionState, agents: list[str]) -> dict[str, str | None]:
    """Those of ``agents`` with editable blueprint skills, each with its whole blueprint."""
    return {
        agent: None
        for agent in agents
        if agent in state.agents and state.sections(agent).editable_start < len(state.task(agent))
    }


def plan_synchronize_team(state: MissionState, uploads: TeamUploads) -> Proposal:
    """Every listed robot's blueprint up to its skill, marked as uploading, in one change.

    Raises the first robot's refusal (and nothing is changed) if any robot cannot be
    synchronized as asked; RuleViolation if no robot is listed.
    """
    if not uploads:
        raise RuleViolation("no robot has blueprint skills to synchronize")
    puts: list[PlacedSkill] = []
    summaries = []
    for agent, upto_id in uploads.items():
        proposal = plan_synchronize(state, agent, upto_id)
        puts.extend(proposal.change.put_skills)
        summaries.append(proposal.summary)
    # A team event concerns several agents: "" as the MissionEvent message says.
    agent = next(iter(uploads)) if len(uploads) == 1 else ""
    return Proposal(
        EventKind.SYNC_REQUESTED, agent, "; ".join(summaries), Change(put_skills=tuple(puts))
    )
