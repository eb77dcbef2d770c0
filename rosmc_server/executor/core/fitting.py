"""The robot's skills fitted to its library: parameters are declared once, in the library.

At start the executor takes the skill implementations of its ``~skills`` module and the
skills the library gives the robot's model, and makes one :class:`SkillType` per library
skill: an implementation's, or a binding's (a skill run through a ROS action, service or
topic, built by the ROS adapter). The parameter types come from the library; an
implementation that declares parameters of its own must agree with it, or the executor
refuses to start with a :class:`SkillSetupError` naming the skill and the parameter.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, replace

from rosmc_server.core import (
    AgentKind,
    Library,
    NotFound,
    ParamType,
    SkillSetupError,
    SkillSpec,
)

from .skills import SkillType


@dataclass(frozen=True)
class FittedSkills:
    """What the robot runs, and what the library lists that nothing implements."""

    types: dict[str, SkillType]
    unimplemented: tuple[str, ...] = ()
    unlisted: tuple[str, ...] = ()
    """Implementations the library does not give this robot's model (never uploaded)."""


def parameter_types(spec: SkillSpec) -> dict[str, ParamType]:
    """``{name: ParamType}`` of a library skill, as a :class:`SkillType` declares them."""
    return {p.name: p.type for p in spec.parameters}


def fit_to_library(
    library: Library,
    agent: str,
    implementations: Mapping[str, SkillType],
    bind: Callable[[SkillSpec], SkillType],
) -> FittedSkills:
    """One SkillType per library skill of ``agent``; SkillSetupError if one disagrees."""
    try:
        member = library.agent(agent)
    except NotFound as error:
        raise SkillSetupError(f"library '{library.name}': {error}") from error
    if member.kind is AgentKind.STATIC:
        raise SkillSetupError(f"'{agent}' is a static agent in library '{library.name}'")
    specs = library.skills_of(agent)
    types: dict[str, SkillType] = {}
    missing = []
    for name, spec in specs.items():
        implementation = implementations.get(name)
        if spec.binding is not None:
            if implementation is not None:
                raise SkillSetupError(
                    f"skill '{name}' is bound to {spec.binding.describe()} in library "
                    f"'{library.name}' and implemented in code too: keep one of them"
                )
            types[name] = bind(spec)
        elif implementation is not None:
            types[name] = fitted(implementation, spec)
        else:
            missing.append(name)
    unlisted = tuple(sorted(set(implementations) - set(specs)))
    return FittedSkills(types, tuple(missing), unlisted)


def fitted(implementation: SkillType, spec: SkillSpec) -> SkillType:
    """``implementation`` with the library's parameters; SkillSetupError if they disagree."""
    declared = parameter_types(spec)
    for name, ptype in implementation.parameters.items():
        if name not in declared:
            known = ", ".join(declared) or "none"
            raise SkillSetupError(
                f"the implementation of skill '{spec.name}' reads parameter '{name}', which "
                f"the library does not declare (it declares: {known})"
            )
        if declared[name] is not ptype:
            raise SkillSetupError(
                f"the implementation of skill '{spec.name}' reads parameter '{name}' as "
                f"{ptype.name.lower()}, but the library declares it "
                f"{declared[name].name.lower()}"
            )
    return replace(
        implementation,
        parameters=declared,
        description=implementation.description or spec.description,
    )
