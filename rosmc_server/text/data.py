"""Missions, libraries and events as plain data with stable keys (for ``--json``)."""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from ..core import (
    AgentKind,
    Library,
    MissionEvent,
    MissionState,
    ParameterSpec,
    SkillInstance,
    SkillSpec,
    TaskMarker,
)
from ..core.robots.agent_status import AgentStatus
from ..core.skills.params import value_to_data
from ..core.world.site_source import SiteInForce


def mission_to_json(
    state: MissionState,
    library: Library | None = None,
    statuses: Mapping[str, AgentStatus] | None = None,
) -> dict[str, Any]:
    """The mission as plain data: revision, library, agents, barriers, markers.

    Agents come in library order (static ones with no skills); each has a
    ``link`` entry (None if unknown) when ``statuses`` is given.
    """
    kinds = {a.name: (a.kind.name.lower(), a.model) for a in library.agents} if library else {}
    names = list(kinds) + [agent for agent in state.agents if agent not in kinds]
    agents = []
    for name in names:
        kind, model = kinds.get(name, ("dynamic", ""))
        entry: dict[str, Any] = {"name": name, "kind": kind, "model": model}
        if statuses is not None:
            status = statuses.get(name)
            entry["link"] = agent_status_to_json(status) if status else None
        task = state.task(name) if name in state.agents else ()
        entry["skills"] = [skill_to_json(skill) for skill in task]
        agents.append(entry)
    return {
        "revision": state.revision,
        "library": state.library,
        "agents": agents,
        "barriers": [
            {
                "id": b.id,
                "skills": list(b.skill_ids),
                "agents": [state.locate(s)[0] if state.has_skill(s) else "" for s in b.skill_ids],
            }
            for b in state.barriers
        ],
        "markers": [marker_to_json(marker) for marker in state.markers],
    }


def skill_to_json(skill: SkillInstance) -> dict[str, Any]:
    """One skill instance as plain data (statuses and transfers by name)."""
    return {
        "id": skill.id,
        "skill": skill.skill,
        "label": skill.label,
        "status": skill.status.name,
        "transfer": skill.transfer.name,
        "resolution": skill.resolution.name,
        "attempt": skill.attempt,
        "params": {name: value_to_data(value) for name, value in skill.params.items()},
        "bindings": dict(skill.bindings),
        "status_text": skill.status_text,
        "timeout": skill.timeout,
        "max_retries": skill.max_retries,
    }


def marker_to_json(marker: TaskMarker) -> dict[str, Any]:
    """One task marker as plain data."""
    return {
        "name": marker.name,
        "type": marker.type.name.lower(),
        "pose": marker.pose.to_dict(),
        "vertices": [vertex.to_dict() for vertex in marker.vertices],
    }


def agent_status_to_json(status: AgentStatus) -> dict[str, Any]:
    """A robot's link and telemetry state as plain data."""
    return {
        "state": status.link,
        "last_heard": status.last_heard,
        "round_trip": status.round_trip,
        "commands_in_flight": status.commands_in_flight,
        "commands_waiting": status.commands_waiting,
        "waiting_for": status.waiting_for,
        "hash_mismatch": status.hash_mismatch,
        "battery": status.battery,
        "wifi_signal": status.wifi_signal,
        "in_coverage": status.in_coverage,
        "pose": status.pose.to_dict() if status.pose else None,
        "current_skill": status.current_skill,
        "current_status": status.current_status.name if status.current_status else None,
        "executor_state": status.executor_state,
        "waiting_on": status.waiting_on,
        "policy": status.policy,
        "coverage_warning": status.coverage_warning,
        "radio_dropped": status.radio_dropped,
        "hold": status.hold.value,
        "barrier_wait": status.barrier_wait,
    }


def library_to_json(library: Library) -> dict[str, Any]:
    """The library as plain data: every agent with its skills and parameter schemas."""
    agents = []
    for agent in library.agents:
        skills = library.skills_of(agent.name) if agent.kind is AgentKind.DYNAMIC else {}
        agents.append(
            {
                "name": agent.name,
                "kind": agent.kind.name.lower(),
                "model": agent.model,
                "description": agent.description,
                "skills": [_skill_spec_to_json(skill) for skill in skills.values()],
            }
        )
    return {"name": library.name, "agents": agents}


def _skill_spec_to_json(skill: SkillSpec) -> dict[str, Any]:
    return {
        "name": skill.name,
        "description": skill.description,
        "estimated_duration": skill.estimated_duration,
        "parameters": [_parameter_to_json(p) for p in skill.parameters],
    }


def _parameter_to_json(param: ParameterSpec) -> dict[str, Any]:
    return {
        "name": param.name,
        "type": param.type.name.lower(),
        "default": value_to_data(param.default),
        "min": param.minimum,
        "max": param.maximum,
        "choices": [value_to_data(c) for c in param.choices],
        "unit": param.unit,
        "description": param.description,
        "marker": param.marker_type.name.lower() if param.marker_type is not None else None,
        "check": param.check_target.value if param.check_target is not None else None,
    }


def event_to_json(event: MissionEvent) -> dict[str, Any]:
    """One mission event as plain data (for ``rosmc watch --json``)."""
    return {
        "revision": event.revision,
        "kind": event.kind.name,
        "agent": event.agent,
        "summary": event.summary,
        "stamp": event.stamp,
    }


def site_to_json(source: SiteInForce) -> dict[str, Any]:
    """The site map in force as JSON data: its name, sender, when taken, and what it holds."""
    x_min, x_max, y_min, y_max = source.site.bounds
    return {
        "name": source.site.name,
        "sender": source.sender,
        "received": source.received,
        "bounds": {"x_min": x_min, "x_max": x_max, "y_min": y_min, "y_max": y_max},
        "obstacles": len(source.site.obstacles),
        "robots": len(source.site.robots),
    }
