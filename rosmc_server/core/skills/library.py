"""The skill library: which agents exist and what each can be asked to do.

A library is a YAML file (``rosmc_library: 1``) with ``models`` (the skills of
each agent model, each with typed parameters) and ``agents`` (the team: name,
dynamic or static, model). A malformed file is refused with an error naming
the file, the key and the problem.
"""

from __future__ import annotations

import enum
from collections.abc import Mapping
from dataclasses import dataclass, field, replace
from pathlib import Path

import yaml

from ..documents.documents import DocumentReader, load_yaml, yaml_problem
from ..errors import InvalidRequest, LibraryError, NotFound, RuleViolation
from ..validation import excerpt
from ..world.site import SiteCheck
from .bindings import BindingSpec, read_binding
from .library_extends import merge_extension
from .package_paths import PackageFinder, PackagePath, resolve_reference
from .params import (
    COMPATIBLE_MARKERS,
    MARKER_PARAM_TYPE,
    MarkerType,
    ParamType,
    Value,
    check_value,
    quick_value,
)
from .policy import LostLinkPolicy

LIBRARY_VERSION = 1


class AgentKind(enum.IntEnum):
    """Dynamic agents (robots) execute skills; static agents are known objects."""

    DYNAMIC = 0
    STATIC = 1


@dataclass(frozen=True)
class ParameterSpec:
    """Schema of one skill parameter."""

    name: str
    type: ParamType
    default: Value
    minimum: float | None = None
    maximum: float | None = None
    choices: tuple[Value, ...] = ()
    unit: str = ""
    description: str = ""
    marker_type: MarkerType | None = None
    check_target: SiteCheck | None = None

    def check(self, raw: object, skill: str) -> Value:
        """Check a value for this parameter of ``skill``; return it normalized.

        A parameter an area marker fills must be a polygon: at least three
        ``{x, y}`` points, since that is what robots receive from a marker.
        """
        quick = quick_value(self.type, raw, self.minimum, self.maximum, self.choices)
        if quick is not None:  # never a list: an area's polygon takes the full check
            return quick
        what = f"parameter '{self.name}' of skill '{skill}'"
        value = check_value(self.type, raw, what, self.minimum, self.maximum, self.choices)
        if self.marker_type is MarkerType.AREA:
            check_polygon(value, what)
        return value

    def accepts_marker(self, marker_type: MarkerType) -> bool:
        """Whether a task marker of ``marker_type`` may fill this parameter."""
        if self.marker_type is None:
            return False
        return marker_type in COMPATIBLE_MARKERS[self.marker_type]


@dataclass(frozen=True)
class SkillSpec:
    """A skill an agent model implements."""

    name: str
    parameters: tuple[ParameterSpec, ...] = ()
    description: str = ""
    estimated_duration: float = 0.0
    binding: BindingSpec | None = None
    """Set when the skill runs through a ROS action, service or topic (no code)."""

    def parameter(self, name: str) -> ParameterSpec:
        """The parameter called ``name``; NotFound if the skill has none."""
        for spec in self.parameters:
            if spec.name == name:
                return spec
        known = ", ".join(spec.name for spec in self.parameters) or "none"
        raise NotFound(f"skill '{self.name}' has no parameter {excerpt(name)} (it has: {known})")

    def defaults(self) -> dict[str, Value]:
        """Every parameter's default value."""
        return {spec.name: spec.default for spec in self.parameters}


@dataclass(frozen=True)
class AgentSpec:
    """One member of the team."""

    name: str
    kind: AgentKind
    model: str
    description: str = ""


@dataclass(frozen=True)
class Library:
    """Agents and the skills of each agent model."""

    name: str
    agents: tuple[AgentSpec, ...]
    models: Mapping[str, Mapping[str, SkillSpec]] = field(default_factory=dict)
    lost_link: Mapping[str, LostLinkPolicy] = field(default_factory=dict)
    """The default lost-link policy of each model that declares one."""

    def default_policy(self, agent: str) -> LostLinkPolicy | None:
        """The lost-link policy the library declares for ``agent``'s model, if any."""
        return self.lost_link.get(self.agent(agent).model)

    def agent(self, name: str) -> AgentSpec:
        """The agent called ``name``; NotFound otherwise."""
        for agent in self.agents:
            if agent.name == name:
                return agent
        known = ", ".join(agent.name for agent in self.agents)
        raise NotFound(f"there is no agent {excerpt(name)} (agents: {known})")

    @property
    def dynamic_agents(self) -> tuple[str, ...]:
        """Names of the agents that execute skills, in library order."""
        return tuple(a.name for a in self.agents if a.kind is AgentKind.DYNAMIC)

    def skills_of(self, agent: str) -> Mapping[str, SkillSpec]:
        """The skills ``agent`` can execute."""
        return self.models.get(self.agent(agent).model, {})

    def skill(self, agent: str, skill: str) -> SkillSpec:
        """The skill ``skill`` of ``agent``; NotFound or RuleViolation otherwise."""
        spec = self.agent(agent)
        if spec.kind is AgentKind.STATIC:
            raise RuleViolation(f"'{agent}' is a static agent and cannot execute skills")
        skills = self.models.get(spec.model, {})
        if skill not in skills:
            known = ", ".join(sorted(skills)) or "none"
            raise NotFound(
                f"agent {excerpt(agent)} has no skill {excerpt(skill)} (it has: {known})"
            )
        return skills[skill]


def check_polygon(value: object, what: str) -> None:
    """Raise InvalidRequest unless ``value`` is a list of at least three {x, y} points."""
    if not isinstance(value, list) or len(value) < 3:
        raise InvalidRequest(f"{what} must list at least three corners")
    for index, point in enumerate(value):
        ok = isinstance(point, dict) and all(
            isinstance(point.get(axis), (int, float)) and not isinstance(point.get(axis), bool)
            for axis in ("x", "y")
        )
        if not ok:
            raise InvalidRequest(f"corner {index} of {what} must be a point with x and y")


def load_library(path: str | Path, *, find_package: PackageFinder | None = None) -> Library:
    """Read a library YAML file; LibraryError names the file, key and problem.

    A library with ``extends: OTHER.yaml`` (a path from its own folder, or a package's file:
    ``package://PKG/PATH``, ``$(find PKG)/PATH``) is that library plus its own agents,
    models and skills (see :mod:`.library_extends`). ``find_package`` finds a package's
    folder (:mod:`.package_paths`; by default through the environment's ROS_PACKAGE_PATH).
    """
    finder = find_package if find_package is not None else PackagePath.from_environ()
    return library_from_dict(_library_data(Path(path), (), finder), str(path))


def _library_data(path: Path, chain: tuple[Path, ...], find_package: PackageFinder) -> object:
    """The file's parsed data, with the libraries it extends merged in and checked."""
    source = str(path)
    try:
        text = path.read_text(encoding="utf-8")
    except OSError as error:
        raise LibraryError(f"{source}: cannot read the library file ({error.strerror})") from error
    except UnicodeDecodeError as error:
        raise LibraryError(f"{source}: the file is not UTF-8 text (byte {error.start})") from error
    try:
        data = load_yaml(text)
    except yaml.YAMLError as error:
        raise LibraryError(f"{source}: not valid YAML ({yaml_problem(error)})") from error
    if not isinstance(data, Mapping) or "extends" not in data:
        return data
    reader = DocumentReader(source, LibraryError)
    try:
        base_path = resolve_reference(
            reader.text(data["extends"], "extends"), path.parent, find_package
        )
    except LibraryError as error:
        raise LibraryError(f"{source}: {error}") from error
    chain = (*chain, path.resolve())
    if base_path.resolve() in chain:
        reader.fail("extends", f"{base_path.name} extends this library again (a loop)")
    base = _library_data(base_path, chain, find_package)
    library_from_dict(base, str(base_path))  # its own mistakes are named in its own file
    return merge_extension(base, data, reader)


def library_from_dict(data: object, source: str = "<library>") -> Library:
    """Build a library from parsed YAML data, checking every key."""
    reader = DocumentReader(source, LibraryError)
    top = reader.mapping(
        data, "", required={"rosmc_library", "name", "models", "agents"}, optional=set()
    )
    version = top["rosmc_library"]
    if isinstance(version, bool) or version != LIBRARY_VERSION:
        reader.fail("rosmc_library", f"unsupported version {top['rosmc_library']!r}")
    name = reader.text(top["name"], "name")
    models_data = reader.mapping(top["models"], "models")
    models = {
        reader.text(model, f"models.{model}"): _read_model(reader, raw, f"models.{model}")
        for model, raw in models_data.items()
    }
    policies = {
        model: _read_policy(reader, models[model], raw["lost_link"], f"models.{model}.lost_link")
        for model, raw in models_data.items()
        if isinstance(raw, Mapping) and "lost_link" in raw
    }
    agents = _read_agents(reader, top["agents"], models)
    return Library(name=name, agents=agents, models=models, lost_link=policies)


def _read_policy(
    reader: DocumentReader, skills: Mapping[str, SkillSpec], raw: object, key: str
) -> LostLinkPolicy:
    """A model's default lost-link policy, its skill checked against the model's skills."""
    try:
        policy = LostLinkPolicy.from_dict(raw)
    except InvalidRequest as error:
        reader.fail(key, str(error))
    if not policy.kind.runs_skill:
        return policy
    if policy.skill not in skills:
        reader.fail(f"{key}.skill", f"names no skill of this model ({policy.skill!r})")
    try:
        return policy.checked_against(skills[policy.skill])
    except (InvalidRequest, NotFound) as error:
        reader.fail(key, str(error))


def _read_agents(
    reader: DocumentReader, raw: object, models: Mapping[str, Mapping[str, SkillSpec]]
) -> tuple[AgentSpec, ...]:
    agents: list[AgentSpec] = []
    for name, entry in reader.mapping(raw, "agents").items():
        key = f"agents.{name}"
        body = reader.mapping(entry, key, required={"kind", "model"}, optional={"description"})
        kinds = {kind.name.lower(): kind for kind in AgentKind}
        if body["kind"] not in kinds:
            reader.fail(f"{key}.kind", f"must be dynamic or static, got {body['kind']!r}")
        model = reader.text(body["model"], f"{key}.model")
        if model not in models and kinds[body["kind"]] is AgentKind.DYNAMIC:
            reader.fail(f"{key}.model", f"names no model in 'models' ({model!r})")
        description = reader.text(body.get("description", ""), f"{key}.description", empty=True)
        agents.append(AgentSpec(str(name), kinds[body["kind"]], model, description))
    if not agents:
        reader.fail("agents", "the library declares no agents")
    return tuple(agents)


def _read_model(reader: DocumentReader, raw: object, key: str) -> dict[str, SkillSpec]:
    body = reader.mapping(raw, key, required={"skills"}, optional={"description", "lost_link"})
    skills: dict[str, SkillSpec] = {}
    for name, entry in reader.mapping(body["skills"], f"{key}.skills").items():
        skills[name] = _read_skill(reader, name, entry, f"{key}.skills.{name}")
    return skills


def _read_skill(reader: DocumentReader, name: str, raw: object, key: str) -> SkillSpec:
    body = reader.mapping(
        raw, key, optional={"description", "duration", "parameters", "binding"}, allow_none=True
    )
    params_raw = reader.mapping(body.get("parameters") or {}, f"{key}.parameters")
    parameters = tuple(
        _read_parameter(reader, name, pname, entry, f"{key}.parameters.{pname}")
        for pname, entry in params_raw.items()
    )
    binding = None
    if "binding" in body:
        binding = read_binding(reader, body["binding"], f"{key}.binding", params_raw)
    duration = reader.number(body.get("duration", 0.0), f"{key}.duration")
    if duration < 0:
        reader.fail(f"{key}.duration", "must not be negative")
    description = reader.text(body.get("description", ""), f"{key}.description", empty=True)
    return SkillSpec(name, parameters, description, duration, binding)


def _read_parameter(
    reader: DocumentReader, skill: str, name: str, raw: object, key: str
) -> ParameterSpec:
    body = reader.mapping(
        raw,
        key,
        required={"type", "default"},
        optional={"min", "max", "choices", "unit", "description", "marker", "check"},
    )
    types = {ptype.name.lower(): ptype for ptype in ParamType}
    if body["type"] not in types:
        reader.fail(f"{key}.type", f"must be one of {', '.join(types)}, got {body['type']!r}")
    ptype = types[body["type"]]
    minimum = reader.number(body["min"], f"{key}.min") if "min" in body else None
    maximum = reader.number(body["max"], f"{key}.max") if "max" in body else None
    if minimum is not None and maximum is not None and minimum > maximum:
        reader.fail(key, f"min {minimum:g} is greater than max {maximum:g}")
    if (minimum is not None or maximum is not None) and ptype not in (
        ParamType.INT,
        ParamType.FLOAT,
    ):
        reader.fail(key, "min and max apply to int and float parameters only")
    choices = reader.items(body.get("choices", []), f"{key}.choices")
    try:
        checked_choices = tuple(check_value(ptype, c, f"{key}.choices") for c in choices)
        spec = ParameterSpec(
            name=name,
            type=ptype,
            default=check_value(ptype, body["default"], f"{key}.default"),
            minimum=minimum,
            maximum=maximum,
            choices=checked_choices,
            unit=reader.text(body.get("unit", ""), f"{key}.unit", empty=True),
            description=reader.text(body.get("description", ""), f"{key}.description", empty=True),
            marker_type=_read_marker_type(reader, body.get("marker"), ptype, f"{key}.marker"),
        )
        spec.check(spec.default, skill)
    except InvalidRequest as error:
        reader.fail(f"{key}.default", str(error))
    return replace(spec, check_target=_read_check(reader, body.get("check"), spec, key))


def _read_marker_type(
    reader: DocumentReader, raw: object, ptype: ParamType, key: str
) -> MarkerType | None:
    if raw is None:
        return None
    names = {marker.name.lower(): marker for marker in MarkerType}
    if raw not in names:
        reader.fail(key, f"must be one of {', '.join(names)}, got {raw!r}")
    marker = names[str(raw)]
    if MARKER_PARAM_TYPE[marker] is not ptype:
        expected = MARKER_PARAM_TYPE[marker].name.lower()
        reader.fail(key, f"a {marker.name.lower()} marker fills {expected} parameters only")
    return marker


def _read_check(
    reader: DocumentReader, raw: object, spec: ParameterSpec, key: str
) -> SiteCheck | None:
    """A target check: on a pose, or on an area (a list an area marker fills)."""
    if raw is None:
        return None
    names = {check.value: check for check in SiteCheck}
    if raw not in names:
        reader.fail(f"{key}.check", f"must be one of {', '.join(names)}, got {raw!r}")
    check = names[str(raw)]
    area = spec.type is ParamType.LIST and spec.marker_type is MarkerType.AREA
    if spec.type is not ParamType.POSE and not area:
        reader.fail(f"{key}.check", "applies to pose parameters and areas (marker: area) only")
    if area and check is SiteCheck.REACHABLE_GROUND:
        reader.fail(f"{key}.check", "reachable_ground checks one point; an area takes on_site")
    return check
