"""Missions, libraries, markers and events as text for people.

One robot's task under another (synchronized section, a rule, the
blueprint), status marks and tags; values in the ``key=value`` form that
``rosmc add`` reads back.
"""

from __future__ import annotations

import json
import math
from collections.abc import Iterable, Mapping

from ..core import (
    AgentKind,
    Library,
    MissionEvent,
    MissionState,
    Pose,
    SkillInstance,
    SkillSpec,
    SkillStatus,
    TaskMarker,
    Transfer,
    Value,
)
from ..core.model.control import HoldCause
from ..core.robots.agent_status import AgentStatus
from ..core.robots.link import LinkStatus
from ..core.views import holding
from ..core.views.vocabulary import STATUS_MARKS, counted, dbm, number, percent, wifi_words

_RULE = "    " + "-" * 56


def format_tasks(
    state: MissionState,
    title: str | None = None,
    statuses: Mapping[str, AgentStatus] | None = None,
    verbose: bool = False,
) -> str:
    """Every robot's task: synchronized section, a rule, then the blueprint.

    With ``statuses`` (even empty), each robot gets a link/telemetry line; with
    ``verbose``, each skill its parameter values in ``key=value`` form.
    """
    if title is None:
        header = f"mission at revision {state.revision} (library {state.library})"
    else:
        header = f"=== {title} (revision {state.revision}) ==="
    lines = [header]
    for agent in state.agents:
        lines.append(f"  {agent}")
        if statuses is not None:
            lines.append(f"    {format_agent_status(statuses.get(agent))}")
            lines.extend(f"    {line}" for line in hold_lines(state, statuses.get(agent)))
        task = state.task(agent)
        synced_end = state.sections(agent).synced_end
        for index, skill in enumerate(task):
            if index == synced_end:
                lines.append(_RULE + " blueprint")
            lines.append(_skill_line(state, skill))
            if verbose and skill.params:
                lines.append(f"         {format_params(skill)}")
        if synced_end == len(task):
            lines.append(_RULE + " blueprint (empty)")
    return "\n".join(lines)


def hold_lines(state: MissionState, status: AgentStatus | None) -> list[str]:
    """What a robot holding after its lost-link policy blocks and the command that frees
    it, and what a robot waiting at a barrier waits for, since how long (none: [])."""
    if status is None:
        return []
    agent, out = status.agent, []

    def find(skill_id: str) -> SkillInstance | None:
        return state.skill(skill_id) if state.has_skill(skill_id) else None

    if status.hold is not HoldCause.NONE:
        partners = holding.barrier_partners(state.barriers, find, agent)
        sentence = holding.hold_sentence(agent, status.hold, partners, status.link is LinkStatus.UP)
        out.append(f"HOLDING: {sentence} Free it: rosmc resume {agent}")
    current = find(status.current_skill) if status.current_skill else None
    barrier = state.barrier_of(current.id) if current is not None else None
    if current is not None and barrier is not None and current.status is SkillStatus.SYNCWAITING:
        members = [s for i in barrier.skill_ids if (s := find(i)) is not None]
        missing = holding.not_arrived(members, agent)
        out.append(f"{agent} {holding.wait_sentence(missing, barrier.id, status.barrier_wait)}")
    return out


def _skill_line(state: MissionState, skill: SkillInstance) -> str:
    barrier = state.barrier_of(skill.id)
    tags = [f"barrier {barrier.id}"] if barrier else []
    if skill.transfer is Transfer.UPLOADING:
        tags.append("uploading")
    elif skill.transfer is Transfer.REMOVING:
        tags.append("removing")
    if skill.attempt > 1:
        tags.append(f"attempt {skill.attempt}")
    if skill.resolution:
        tags.append(skill.resolution.name.lower())
    if skill.status_text:
        tags.append(skill.status_text)
    mark = STATUS_MARKS[skill.status]
    return f"    {mark} {skill.id:<24} {skill.label:<20} {', '.join(tags)}"


def format_agent_status(status: AgentStatus | None) -> str:
    """One line: link state, telemetry and executor state of a robot ("link unknown" if None)."""
    if status is None:
        return "link unknown"
    link = f"link {status.link}"
    if status.link is LinkStatus.UNKNOWN:
        link = "link never heard since the server started (commands wait for it)"
    details = []
    if status.last_heard >= 0:
        details.append(f"heard {status.last_heard:.1f} s ago")
    if status.round_trip >= 0:
        details.append(f"round trip {status.round_trip * 1000:.0f} ms")
    if status.commands_in_flight and not status.commands_waiting:
        details.append(f"{counted(status.commands_in_flight, 'command')} in flight")
    if status.hash_mismatch:
        details.append("repairing queue")
    parts = [f"{link} ({', '.join(details)})" if details else link]
    if status.commands_waiting:
        parts.append(status.waiting_text)
    if status.battery is not None:
        parts.append(f"battery {percent(status.battery)}")
    if status.wifi_signal is not None:
        words = wifi_words(status.wifi_signal, status.in_coverage)
        parts.append(f"Wi-Fi {words} ({dbm(status.wifi_signal)})")
    if status.pose is not None:
        pose = status.pose
        parts.append(f"at ({number(pose.x, 3)}, {number(pose.y, 3)}, {number(pose.z, 3)})")
        parts.append("in coverage" if status.in_coverage else "out of coverage")
    if status.executor_state:
        parts.append(f"executor {status.executor_state}")
    if status.waiting_on:
        parts.append(f"waiting on {status.waiting_on}")
    if status.policy:
        parts.append(status.policy)
    if status.coverage_warning:
        parts.append(f"WARNING: {status.coverage_warning}")
    if status.radio_dropped:
        parts.append(f"WARNING: {status.radio_text}")
    return ", ".join(parts)


def format_value(value: Value) -> str:
    """A parameter value in the form ``rosmc add key=value`` reads back."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, float):
        return _num(value)
    if isinstance(value, Pose):
        return ",".join(_num(getattr(value, name)) for name in Pose.FIELDS)
    if isinstance(value, (list, dict)):
        return json.dumps(value, separators=(",", ":"))
    return str(value)


def format_params(skill: SkillInstance) -> str:
    """A skill's parameters as ``key=value`` (``key=@MARKER`` for bound ones)."""
    return "  ".join(
        f"{name}=@{skill.bindings[name]}" if name in skill.bindings else f"{name}={format_value(v)}"
        for name, v in skill.params.items()
    )


def _num(value: float) -> str:
    """A number exactly, as ``rosmc add`` reads it back (:func:`number` rounds for people)."""
    if math.isfinite(value) and value == int(value) and abs(value) < 1e15:
        return str(int(value))
    return repr(float(value))


def format_markers(markers: Iterable[TaskMarker]) -> str:
    """One line per task marker: name, type and where it is."""
    lines = []
    for marker in markers:
        pose = marker.pose
        where = f"({number(pose.x, 3)}, {number(pose.y, 3)}, {number(pose.z, 3)})"
        if marker.vertices:
            where = f"{len(marker.vertices)} vertices around {where}"
        elif pose.yaw:
            where += f" yaw {number(pose.yaw, 3)}"
        lines.append(f"{marker.name:<24} {marker.type.name.lower():<9} {where}")
    return "\n".join(lines) if lines else "(no task markers)"


def format_library(library: Library, agent: str | None = None) -> str:
    """Agents, their skills and every parameter's schema (one agent if ``agent`` is given)."""
    lines = [f"library {library.name}"]
    agents = [library.agent(agent)] if agent else list(library.agents)
    for spec in agents:
        about = f": {spec.description}" if spec.description else ""
        lines.append(f"{spec.name} ({spec.kind.name.lower()}, model {spec.model}){about}")
        if spec.kind is AgentKind.DYNAMIC:
            for skill in library.skills_of(spec.name).values():
                lines.extend(_skill_spec_lines(skill))
    return "\n".join(lines)


def _skill_spec_lines(skill: SkillSpec) -> list[str]:
    about = f": {skill.description}" if skill.description else ""
    lines = [f"  {skill.name} (about {_num(skill.estimated_duration)} s){about}"]
    for param in skill.parameters:
        text = f"    {param.name}: {param.type.name.lower()} = {format_value(param.default)}"
        if param.unit:
            text += f" {param.unit}"
        if param.minimum is not None or param.maximum is not None:
            low = "" if param.minimum is None else _num(param.minimum)
            high = "" if param.maximum is None else _num(param.maximum)
            text += f", range {low}..{high}"
        if param.choices:
            text += f", one of {'|'.join(format_value(c) for c in param.choices)}"
        if param.marker_type is not None:
            text += f", marker {param.marker_type.name.lower()}"
        if param.check_target is not None:
            text += f", check {param.check_target.value}"
        if param.description:
            text += f"  # {param.description}"
        lines.append(text)
    return lines


def format_event(event: MissionEvent) -> str:
    """One line per mission event: revision, kind, agent and summary."""
    return f"r{event.revision:<5} {event.kind.name:<17} {event.agent or '-':<18} {event.summary}"
