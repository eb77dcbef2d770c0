"""The skill library <-> messages (the server sends it; clients read it back).

Part of :mod:`rosmc_server.conversions`, the one boundary between the ``rosmc``
messages and the core.
"""

from __future__ import annotations

import json

import rosmc.msg as wire
import yaml

from ..core import (
    AgentKind,
    AgentSpec,
    InvalidRequest,
    Library,
    LostLinkPolicy,
    MarkerType,
    ParameterSpec,
    ParamType,
    SkillSpec,
    Value,
)
from ..core.world.site import SiteCheck
from .values import param_from_msg, param_to_msg


def parameter_spec_to_msg(spec: ParameterSpec) -> wire.ParameterSpec:
    """A parameter schema as ``rosmc/ParameterSpec``."""
    return wire.ParameterSpec(
        name=spec.name,
        type=int(spec.type),
        default_value=param_to_msg(spec.name, spec.default),
        has_min=spec.minimum is not None,
        min=spec.minimum if spec.minimum is not None else 0.0,
        has_max=spec.maximum is not None,
        max=spec.maximum if spec.maximum is not None else 0.0,
        choices=[str(choice) for choice in spec.choices],
        unit=spec.unit,
        description=spec.description,
        marker_type=spec.marker_type.name if spec.marker_type is not None else "",
        check=spec.check_target.value if spec.check_target is not None else "",
    )


def library_to_msg(library: Library) -> wire.Library:
    """The library as ``rosmc/Library``."""
    return wire.Library(
        name=library.name,
        agents=[
            wire.AgentSpec(name=a.name, kind=int(a.kind), model=a.model, description=a.description)
            for a in library.agents
        ],
        skill_sets=[
            wire.SkillSet(
                model=model,
                skills=[_skill_spec_to_msg(s) for s in skills.values()],
                lost_link=_policy_to_text(library.lost_link.get(model)),
            )
            for model, skills in library.models.items()
        ],
    )


def _skill_spec_to_msg(spec: SkillSpec) -> wire.SkillSpec:
    return wire.SkillSpec(
        name=spec.name,
        description=spec.description,
        parameters=[parameter_spec_to_msg(p) for p in spec.parameters],
        estimated_duration=spec.estimated_duration,
    )


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
        policies = {
            s.model: LostLinkPolicy.from_dict(json.loads(s.lost_link))
            for s in msg.skill_sets
            if s.lost_link
        }
    except (ValueError, KeyError, yaml.YAMLError) as error:
        raise InvalidRequest(f"the server sent a malformed library ({error})") from error
    return Library(msg.name, agents, models, lost_link=policies)


def _policy_to_text(policy: LostLinkPolicy | None) -> str:
    if policy is None:
        return ""
    return json.dumps(policy.to_dict(), separators=(",", ":"))


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
        check_target=_check(msg.check),
    )


def _check(text: str) -> SiteCheck | None:
    # The server runs the checks; a client that does not know a newer one only cannot show it.
    try:
        return SiteCheck(text) if text else None
    except ValueError:
        return None


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
