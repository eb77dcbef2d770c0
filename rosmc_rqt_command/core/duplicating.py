"""Duplicating planned skills: the copies to add after a robot's selected blueprint skills.

A copy has the original's skill, label, options, parameter values and marker bindings (a
bound parameter follows the same marker). The copies go, in the originals' task order,
just after the last selected skill.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

from rosmc_server.core import InvalidRequest, SkillInstance
from rosmc_server.core.skills.params import value_to_data

from .mission_view import MissionView


@dataclass(frozen=True)
class Copy:
    """One ``add_skill`` that copies ``source`` to ``index`` of ``agent``'s task."""

    source: str
    agent: str
    skill: str
    index: int
    params: dict[str, object]
    bindings: dict[str, str]
    label: str
    timeout: float
    max_retries: int


def copies(view: MissionView, skills: Sequence[SkillInstance]) -> list[Copy]:
    """The copies of ``skills``; InvalidRequest (one sentence) if they cannot be copied."""
    if not skills:
        raise InvalidRequest("select the planned skills to duplicate first")
    agents = sorted({s.agent for s in skills})
    if len(agents) > 1:
        raise InvalidRequest(
            f"duplicate one robot's skills at a time (the selection holds {', '.join(agents)})"
        )
    fixed = [s for s in skills if not s.is_editable]
    if fixed:
        raise InvalidRequest(
            f"only planned skills can be duplicated; '{fixed[0].label or fixed[0].skill}' "
            "is on the robot or done"
        )
    ordered = sorted(skills, key=view.position)
    after = view.position(ordered[-1]) + 1
    return [_copy(skill, after + n) for n, skill in enumerate(ordered)]


def _copy(skill: SkillInstance, index: int) -> Copy:
    values = {k: value_to_data(v) for k, v in skill.params.items() if k not in skill.bindings}
    return Copy(
        skill.id,
        skill.agent,
        skill.skill,
        index,
        values,
        dict(skill.bindings),
        skill.label,
        skill.timeout,
        skill.max_retries,
    )
