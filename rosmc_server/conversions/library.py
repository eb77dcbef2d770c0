"""Messages the client receives, as core objects: the library and agent states.

Complements :mod:`rosmc_server.ros.conversions` (which only needs the library's
way *to* the wire on the server side) with the way back for clients.
"""

from __future__ import annotations

import math

import rosmc.msg as wire
import yaml

from ...core import (
    AgentKind,
    AgentSpec,
    AgentStatus,
    InvalidRequest,
    Library,
    MarkerType,
    ParameterSpec,
    ParamType,
    SkillSpec,
    SkillStatus,
    Value,
)
from ..conversions import param_from_msg, pose_from_msg

_LINK_STATES = {wire.LinkState.UP: "up", wire.LinkState.DOWN: "down"}


def library_from_msg(msg: wire.Library) -> Library:
    """``rosmc/Library`` as a core library (InvalidRequest if it is malformed)."""
    try:
        agents = tuple(
            AgentSpec(a.name, AgentKind(a.kind), a.model, a.description) for a in msg.agents
        )
        models = {
            skill_set.model: {s.name: _skill_spec_from_msg(s) for s in skill_set.skills}
            for skill_set in msg.skill_sets
        }
    except (ValueError, KeyError, yaml.YAMLError) as error:
        raise InvalidRequest(f"the server sent a malformed library ({error})") from error
    return Library(msg.name, agents, models)


def _skill_spec_from_msg(msg: wire.SkillSpec) -> SkillSpec:
    return SkillSpec(
        msg.name,
        tuple(_parameter_spec_from_msg(p) for p in msg.parameters),
        msg.description,
        msg.estimated_duration,
    )


def _parameter_spec_from_msg(msg: wire.ParameterSpec) -> ParameterSpec:
    ptype = ParamType(msg.type)
    _, default = param_from_msg(msg.default_value)
    return ParameterSpec(
        name=msg.name,
        type=ptype,
        default=default,  # type: ignore[arg-type]  # normalized by the server
        minimum=msg.min if msg.has_min else None,
        maximum=msg.max if msg.has_max else None,
        choices=tuple(_choice(ptype, text) for text in msg.choices),
        unit=msg.unit,
        description=msg.description,
        marker_type=MarkerType[msg.marker_type.upper()] if msg.marker_type else None,
    )


def _choice(ptype: ParamType, text: str) -> Value:
    # The server sends choices as str(value); read them back per type.
    if ptype is ParamType.STRING:
        return text
    if ptype is ParamType.INT:
        return int(text)
    if ptype is ParamType.FLOAT:
        return float(text)
    if ptype is ParamType.BOOL:
        return text.strip().lower() == "true"
    loaded: Value = yaml.safe_load(text)
    return loaded


def agent_statuses_from_msg(msg: wire.AgentStates) -> dict[str, AgentStatus]:
    """``rosmc/AgentStates`` as one :class:`AgentStatus` per agent."""
    return {state.agent: agent_status_from_msg(state) for state in msg.agents}


def agent_status_from_msg(msg: wire.AgentState) -> AgentStatus:
    """``rosmc/AgentState`` as an :class:`AgentStatus`."""
    telemetry = msg.telemetry
    has_telemetry = bool(telemetry.frame_id) or not telemetry.stamp.is_zero()
    current = msg.current_skill_id
    return AgentStatus(
        agent=msg.agent,
        link=_LINK_STATES.get(msg.link.state, "unknown"),
        last_heard=msg.link.last_heard,
        round_trip=msg.link.round_trip,
        commands_in_flight=msg.link.commands_in_flight,
        hash_mismatch=msg.link.hash_mismatch,
        queue_hash=msg.link.queue_hash,
        robot_queue_hash=msg.link.robot_queue_hash,
        battery=_finite(telemetry.battery),
        wifi_signal=_finite(telemetry.wifi_signal),
        in_coverage=telemetry.in_coverage,
        pose=pose_from_msg(telemetry.pose) if has_telemetry else None,
        current_skill=current,
        current_status=SkillStatus(msg.current_status.value) if current else None,
        executor_state=msg.executor_state,
        waiting_on=msg.waiting_on,
        policy=msg.policy,
    )


def _finite(number: float) -> float | None:
    return float(number) if math.isfinite(number) else None
