"""Blueprint editing: add, edit, delete and reorder skills.

Only the editable blueprint changes here: IDLE skills that are not being
uploaded. Every function validates the whole request before proposing a
change, so a rejected request leaves the mission untouched.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import replace

from ..errors import InvalidRequest, RuleViolation
from ..model.changes import Change, EventKind, PlacedSkill, Proposal, SkillMove
from ..model.model import SkillInstance, TaskMarker
from ..model.state import MissionState
from ..skills.library import Library, SkillSpec
from ..skills.params import ParamType, Value
from ..validation import (
    MAX_LABEL,
    MAX_RETRIES,
    check_one_line,
    check_skill_count,
    check_whole,
    excerpt,
    finite_float,
)
from .barriers import barrier_without, check_moves
from .edit_rules import edit_refusal


def plan_add_skill(
    state: MissionState,
    library: Library,
    new_id: str,
    agent: str,
    skill: str,
    params: Mapping[str, object],
    bindings: Mapping[str, str],
    label: str = "",
    index: int | None = None,
    timeout: float = 0.0,
    max_retries: int = 0,
) -> Proposal:
    """Add ``skill`` to ``agent``'s blueprint (appended, or inserted at ``index``)."""
    spec = library.skill(agent, skill)
    check_skill_count(state.skill_count + 1)
    task = state.task(agent)
    editable_start = state.sections(agent).editable_start
    if index is None:
        index = len(task)
    elif not editable_start <= index <= len(task):
        raise InvalidRequest(
            f"index {index} is outside {agent}'s editable blueprint "
            f"(positions {editable_start} to {len(task)})"
        )
    overlap = sorted(set(params) & set(bindings))
    if overlap:
        raise InvalidRequest(f"parameter '{overlap[0]}' is given both a value and a marker")
    values = spec.defaults()
    values.update(check_params(spec, params))
    values.update(bound_values(state.marker, spec, bindings))
    instance = SkillInstance(
        id=new_id,
        agent=agent,
        skill=skill,
        label=check_label(label, default=skill),
        params=values,
        bindings=dict(bindings),
        timeout=check_timeout(timeout),
        max_retries=check_retries(max_retries),
    )
    where = "appended to" if index == len(task) else f"inserted at position {index} of"
    return Proposal(
        EventKind.SKILL_ADDED,
        agent,
        f"'{new_id}' ({skill}) {where} {agent}'s blueprint",
        Change(put_skills=(PlacedSkill(index, instance),)),
    )


def plan_edit_skill(
    state: MissionState,
    library: Library,
    skill_id: str,
    params: Mapping[str, object],
    bindings: Mapping[str, str | None],
    label: str | None = None,
    timeout: float | None = None,
    max_retries: int | None = None,
) -> Proposal:
    """Change a blueprint skill's label, parameters, marker bindings or options.

    A parameter given a value loses its marker binding; a binding to a marker
    takes the marker's value; a binding to None or "" unbinds (keeps the value).
    """
    old = state.skill(skill_id)
    require_editable(old, "edited")
    if not params and not bindings and label is None and timeout is None and max_retries is None:
        raise InvalidRequest(f"the edit of '{skill_id}' changes nothing")
    overlap = sorted(set(params) & set(bindings))
    if overlap:
        raise InvalidRequest(f"parameter '{overlap[0]}' is given both a value and a marker")
    spec = library.skill(old.agent, old.skill)
    values = dict(old.params)
    values.update(check_params(spec, params))
    new_bindings = {name: marker for name, marker in old.bindings.items() if name not in params}
    to_bind = {name: marker for name, marker in bindings.items() if marker}
    for name in bindings:
        spec.parameter(name)
        new_bindings.pop(name, None)
    values.update(bound_values(state.marker, spec, to_bind))
    new_bindings.update(to_bind)
    new = replace(
        old,
        params=values,
        bindings=new_bindings,
        label=old.label if label is None else check_label(label, default=None),
        timeout=old.timeout if timeout is None else check_timeout(timeout),
        max_retries=old.max_retries if max_retries is None else check_retries(max_retries),
    )
    _, index = state.locate(skill_id)
    return Proposal(
        EventKind.SKILL_EDITED,
        old.agent,
        f"'{skill_id}' ({old.skill}) edited",
        Change(put_skills=(PlacedSkill(index, new),)),
    )


def plan_delete_skills(state: MissionState, skill_ids: Sequence[str]) -> Proposal:
    """Delete blueprint skills; barriers lose them (and dissolve below two members)."""
    if not skill_ids:
        raise InvalidRequest("no skills to delete were given")
    if len(set(skill_ids)) != len(skill_ids):
        raise InvalidRequest("the same skill is listed twice for deletion")
    agents = []
    for skill_id in skill_ids:
        skill = state.skill(skill_id)
        require_editable(skill, "deleted")
        agents.append(skill.agent)
    barriers = barrier_without(state, set(skill_ids))
    change = replace(barriers, removed_skill_ids=tuple(skill_ids))
    agent = agents[0] if len(set(agents)) == 1 else ""
    return Proposal(EventKind.SKILL_DELETED, agent, f"deleted {', '.join(skill_ids)}", change)


def plan_reorder(state: MissionState, agent: str, order: Sequence[str]) -> Proposal:
    """Reorder ``agent``'s editable blueprint; ``order`` is a permutation of its ids.

    The change carries the fewest moves that give the new order, not the order.
    """
    task = state.task(agent)
    start = state.sections(agent).editable_start
    try:  # checks that ``order`` is a permutation of the editable ids as it goes
        moves = state.plan_order(agent, start, order)
    except ValueError:
        raise InvalidRequest(
            f"the new order must list each of {agent}'s {len(task) - start} editable "
            f"blueprint skills exactly once (got {len(order)} ids)"
        ) from None
    return _reordered(state, agent, moves)


def plan_move_skills(state: MissionState, agent: str, moves: Sequence[SkillMove]) -> Proposal:
    """Move skills within ``agent``'s editable blueprint, one move after the other.

    Each move names a skill and its index in the task once moved; both the skill
    and the index must be in the editable blueprint. The cost is the moves', not
    the task's.
    """
    task = state.task(agent)
    if not moves:
        raise InvalidRequest(f"no moves within {agent}'s blueprint were given")
    start = state.sections(agent).editable_start
    for move in moves:
        skill = state.skill(move.skill_id)
        if skill.agent != agent:
            raise InvalidRequest(f"skill '{skill.id}' is on {skill.agent}, not on {agent}")
        require_editable(skill, "moved")
        check_whole(move.index, f"the index to move '{skill.id}' to", start, len(task) - 1)
    return _reordered(state, agent, tuple(moves))


def _reordered(state: MissionState, agent: str, moves: Sequence[SkillMove]) -> Proposal:
    check_moves(state, agent, moves)
    shown = ", ".join(f"'{move.skill_id}' to {move.index}" for move in moves[:3])
    more = f" and {len(moves) - 3} more" if len(moves) > 3 else ""
    return Proposal(
        EventKind.SKILLS_REORDERED,
        agent,
        f"{agent}'s blueprint reordered: moved {shown or 'nothing'}{more}",
        Change(order_agent=agent, moves=moves),
    )


def require_editable(skill: SkillInstance, verb: str) -> None:
    """Raise RuleViolation unless the skill is in the editable blueprint (the rule:
    :func:`~.edit_rules.edit_refusal`)."""
    refusal = edit_refusal(skill, verb)
    if refusal is not None:
        raise RuleViolation(refusal)


def check_params(spec: SkillSpec, params: Mapping[str, object]) -> dict[str, Value]:
    """Check each named value against the skill's schema."""
    return {name: spec.parameter(name).check(raw, spec.name) for name, raw in params.items()}


def bound_values(
    find_marker: Callable[[str], TaskMarker],
    spec: SkillSpec,
    bindings: Mapping[str, str],
) -> dict[str, Value]:
    """The values that bound markers give their parameters (checked against the schema)."""
    values: dict[str, Value] = {}
    for name, marker_name in bindings.items():
        param = spec.parameter(name)
        marker = find_marker(marker_name)
        if not param.accepts_marker(marker.type):
            wanted = param.marker_type.name.lower() if param.marker_type else "no"
            raise RuleViolation(
                f"parameter '{name}' of skill '{spec.name}' takes {wanted} markers, "
                f"not the {marker.type.name.lower()} marker '{marker_name}'"
            )
        values[name] = param.check(marker.value_for(param.type is ParamType.LIST), spec.name)
    return values


def check_label(label: str, default: str | None) -> str:
    """A label: stripped, not too long; ``default`` when empty (or an error if None)."""
    stripped = check_one_line(label, "a label", MAX_LABEL, empty=default is not None)
    return stripped or (default or "")


def check_timeout(timeout: float) -> float:
    """A timeout in seconds: finite and not negative (0 means none)."""
    if isinstance(timeout, bool) or not isinstance(timeout, (int, float)):
        raise InvalidRequest(f"a timeout must be a number of seconds, got {excerpt(timeout)}")
    seconds = finite_float(timeout)
    if seconds is None or seconds < 0:
        raise InvalidRequest(
            f"a timeout must be a finite, non-negative number, got {excerpt(timeout)}"
        )
    return seconds


def check_retries(max_retries: int) -> int:
    """An automatic retry count between 0 and MAX_RETRIES."""
    return check_whole(max_retries, "a retry count", 0, MAX_RETRIES)
