"""Checking a parsed mission document and building the mission from it.

Every entry is checked against the library and the mission rules; the first problem
fails the whole document with one sentence naming the source, the key path and the
problem, and nothing is half-loaded. A well-formed skill entry is read on a quick path
(the same checks, run directly, without composing key paths); any entry the quick path
does not accept is read again with the :class:`~.documents.DocumentReader`, which either
builds the same skill or says precisely what is wrong.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import replace
from typing import Any

from .barriers import describe_cycle, find_deadlock
from .documents import DocumentReader
from .editing import bound_values, check_label, check_params, check_retries, check_timeout
from .errors import MissionFileError, RosmcError
from .library import Library, ParameterSpec, SkillSpec
from .mission_text import MISSION_VERSION
from .model import Barrier, Resolution, SkillInstance, SkillStatus, TaskMarker, Transfer
from .params import MarkerType, Pose, QuickCheck, Value, quick_checker
from .plain_skills import read_plain
from .shared_params import SharedParams
from .state import MissionContent
from .validation import (
    MAX_ATTEMPT,
    MAX_STATUS_TEXT,
    check_corners,
    check_id,
    check_one_line,
    check_skill_count,
    check_time,
    check_whole,
)

_REQUIRED = frozenset({"id", "skill", "params"})
_OPTIONAL = frozenset(
    {
        "label",
        "bindings",
        "status",
        "transfer",
        "resolution",
        "attempt",
        "timeout",
        "max_retries",
        "status_text",
        "started",
        "finished",
    }
)
_KEYS = _REQUIRED | _OPTIONAL
_STATUS: Mapping[str, SkillStatus] = SkillStatus.__members__
_TRANSFER: Mapping[str, Transfer] = Transfer.__members__
_RESOLUTION: Mapping[str, Resolution] = Resolution.__members__
_BLUEPRINT = {(SkillStatus.IDLE, Transfer.NONE, Resolution.NONE)}


def mission_from_dict(
    data: object, library: Library, source: str = "<mission>", *, consume: bool = False
) -> tuple[MissionContent, int]:
    """Build and check a mission from plain data.

    With ``consume``, each task's entries are emptied once read, so that the data and
    the mission built from it are not both held whole (for data nobody else holds).
    """
    reader = DocumentReader(source, MissionFileError)
    if isinstance(data, dict) and "rosmc_mission" in data:
        _check_version(reader, data["rosmc_mission"])  # before anything a new version may change
    top = reader.mapping(
        data,
        "",
        {"rosmc_mission", "library", "revision", "tasks"},
        {"barriers", "markers"},
    )
    _check_version(reader, top["rosmc_mission"])
    if top["library"] != library.name:
        reader.fail("library", f"written for library {top['library']!r}, not {library.name!r}")
    revision = top["revision"]
    if isinstance(revision, bool) or not isinstance(revision, int) or revision < 0:
        reader.fail("revision", f"must be a whole number >= 0, got {revision!r}")
    markers = _read_markers(reader, top.get("markers", []))
    tasks = _read_tasks(reader, top["tasks"], library, markers, consume)
    barriers = _read_barriers(reader, top.get("barriers", []), tasks)
    return MissionContent(library.name, tasks, barriers, markers), revision


def _check_version(reader: DocumentReader, version: object) -> None:
    if isinstance(version, bool) or version != MISSION_VERSION:
        reader.fail("rosmc_mission", f"unsupported mission file version {version!r}")


def _read_markers(reader: DocumentReader, raw: object) -> dict[str, TaskMarker]:
    from .markers import check_marker

    markers: dict[str, TaskMarker] = {}
    for i, entry in enumerate(reader.items(raw, "markers")):
        key = f"markers[{i}]"
        body = reader.mapping(entry, key, {"name", "type", "pose"}, {"vertices"})
        marker_type = reader.enum(MarkerType, body["type"], f"{key}.type")
        vertices = reader.items(body.get("vertices", []), f"{key}.vertices")
        try:
            check_corners(len(vertices), str(body["name"]))
            marker = check_marker(
                TaskMarker(
                    reader.text(body["name"], f"{key}.name"),
                    marker_type,
                    Pose.from_any(body["pose"], f"{key}.pose"),
                    tuple(Pose.from_any(v, f"{key}.vertices") for v in vertices),
                )
            )
        except RosmcError as error:
            reader.fail(key, str(error))
        if marker.name in markers:
            reader.fail(key, f"marker name {marker.name!r} appears twice")
        markers[marker.name] = marker
    return markers


class _TaskReader:
    """Reads the skills of one document, remembering the library's answers."""

    def __init__(
        self, reader: DocumentReader, library: Library, markers: Mapping[str, TaskMarker]
    ) -> None:
        self.reader = reader
        self.library = library
        self.markers = markers
        self._specs: dict[tuple[str, str], SkillSpec] = {}
        # by id(spec): each parameter with its quick check
        self._parameters: dict[int, dict[str, tuple[ParameterSpec, QuickCheck]]] = {}

    def marker(self, name: str) -> TaskMarker:
        """The marker ``name`` of the document."""
        if name not in self.markers:
            raise MissionFileError(f"binds marker {name!r}, which the file does not define")
        return self.markers[name]

    def spec(self, agent: str, skill: str) -> SkillSpec:
        """The library's skill ``skill`` of ``agent`` (NotFound, RuleViolation)."""
        found = self._specs.get((agent, skill))
        if found is None:
            found = self._specs[(agent, skill)] = self.library.skill(agent, skill)
        return found

    def quick(self, raw: object, agent: str) -> SkillInstance | None:
        """The skill a well-formed entry holds, or None (then :meth:`precise` says why).

        The same checks as :meth:`precise`, called directly; a field the entry leaves out
        takes its default without a check.
        """
        if type(raw) is not dict or not _REQUIRED <= raw.keys() <= _KEYS:
            return None
        name, params, bindings = raw["skill"], raw["params"], raw.get("bindings", {})
        label: object = raw.get("label", name)
        status_text: object = raw.get("status_text", "")
        status = _enum(_STATUS, raw["status"]) if "status" in raw else SkillStatus.IDLE
        transfer = _enum(_TRANSFER, raw["transfer"]) if "transfer" in raw else Transfer.NONE
        resolution = (
            _enum(_RESOLUTION, raw["resolution"]) if "resolution" in raw else Resolution.NONE
        )
        if (
            type(name) is not str
            or not name.strip()
            or not isinstance(label, str)
            or not isinstance(status_text, str)
            or type(params) is not dict
            or type(bindings) is not dict
            or status is None
            or transfer is None
            or resolution is None
            or (bindings and not all(type(m) is str and m.strip() for m in bindings.values()))
        ):
            return None
        try:
            check_label(label, None)
            if status_text:
                check_one_line(status_text, "a status text", MAX_STATUS_TEXT, empty=True)
            spec = self.spec(agent, name)
            checked = self.params(spec, params)
            if checked is None:
                return None
            if bindings:
                bound_values(self.marker, spec, bindings)
            return SkillInstance.assemble(
                check_id(raw["id"]),
                agent,
                spec.name,
                label,
                checked,
                dict(bindings),
                status,
                transfer,
                resolution,
                # The optional fields: absent from most entries, then their defaults.
                check_whole(raw["attempt"], "an attempt", 1, MAX_ATTEMPT)
                if "attempt" in raw
                else 1,
                check_timeout(raw["timeout"]) if "timeout" in raw else 0.0,
                check_retries(raw["max_retries"]) if "max_retries" in raw else 0,
                status_text,
                check_time(raw["started"], "a start time") if "started" in raw else 0.0,
                check_time(raw["finished"], "a finish time") if "finished" in raw else 0.0,
            )
        except RosmcError:
            return None

    def params(self, spec: SkillSpec, raw: dict[Any, Any]) -> dict[str, Value] | None:
        """Every parameter of ``spec`` checked (as :func:`~.editing.check_params` checks
        them), or None if one is unknown or missing; RosmcError if a value is wrong."""
        by_name = self._parameters.get(id(spec))  # the library keeps its specs alive
        if by_name is None:
            by_name = self._parameters[id(spec)] = {
                p.name: (p, quick_checker(p.type, p.minimum, p.maximum, p.choices))
                for p in spec.parameters
            }
        if len(raw) != len(by_name):
            return None
        checked: dict[str, Value] = {}
        for name, value in raw.items():
            found = by_name.get(name)
            if found is None:
                return None
            param, quick_check = found
            quick = quick_check(value)
            # Keyed by the library's name: one string shared by every skill, not one each.
            checked[param.name] = param.check(value, spec.name) if quick is None else quick
        return checked

    def precise(self, raw: object, agent: str, key: str, seen: set[str]) -> SkillInstance:
        """The skill an entry holds, or MissionFileError saying what is wrong and where."""
        reader = self.reader
        skill = _read_skill(reader, raw, agent, key)
        try:
            check_loaded_skill(skill)
        except RosmcError as error:
            reader.fail(key, str(error))
        if skill.id in seen:
            reader.fail(f"{key}.id", f"skill id {skill.id!r} appears twice")
        try:
            spec = self.spec(agent, skill.skill)
            checked = check_params(spec, skill.params)
            bound_values(self.marker, spec, skill.bindings)
        except RosmcError as error:
            reader.fail(key, str(error))
        missing = sorted({p.name for p in spec.parameters} - set(checked))
        if missing:
            reader.fail(f"{key}.params", f"is missing {', '.join(missing)}")
        return replace(skill, params=checked)


def _enum(members: Mapping[str, Any], raw: object) -> Any:
    return members.get(raw) if isinstance(raw, str) else None


def _read_tasks(
    reader: DocumentReader,
    raw: object,
    library: Library,
    markers: Mapping[str, TaskMarker],
    consume: bool,
) -> dict[str, list[SkillInstance]]:
    body = reader.mapping(raw, "tasks", set(), None)
    tasks: dict[str, list[SkillInstance]] = {agent: [] for agent in library.dynamic_agents}
    skills = _TaskReader(reader, library, markers)
    try:  # counted before any is read: a flood is refused at once
        check_skill_count(sum(len(e) for e in body.values() if isinstance(e, list)))
    except RosmcError as error:
        reader.fail("tasks", str(error))
    seen: set[str] = set()
    shared = SharedParams(skills.params)  # alike parameters checked once, one dict for all
    for agent, entries in body.items():
        if agent not in tasks:
            reader.fail(f"tasks.{agent}", "names no dynamic agent of the library")
        task = tasks[agent]
        plain = read_plain(entries, agent, skills.spec, shared)
        if plain is not None and seen.isdisjoint(s.id for s in plain):
            ids = {s.id for s in plain}
            if len(ids) == len(plain):  # else read one by one, to name the id given twice
                seen |= ids
                task += plain
                _check_sections(reader, task, f"tasks.{agent}")
                if consume:
                    entries.clear()
                continue
        for i, entry in enumerate(reader.items(entries, f"tasks.{agent}")):
            skill = skills.quick(entry, agent)
            if skill is None:
                skill = skills.precise(entry, agent, f"tasks.{agent}[{i}]", seen)
            if skill.id in seen:
                reader.fail(f"tasks.{agent}[{i}].id", f"skill id {skill.id!r} appears twice")
            seen.add(skill.id)
            task.append(skill)
        _check_sections(reader, task, f"tasks.{agent}")
        if consume:
            entries.clear()
    return tasks


def check_loaded_skill(skill: SkillInstance) -> None:
    """The checks an added or edited skill passes, for a skill read from a file."""
    check_id(skill.id)
    check_label(skill.label, None)
    check_timeout(skill.timeout)
    check_retries(skill.max_retries)
    check_whole(skill.attempt, "an attempt", 1, MAX_ATTEMPT)
    check_one_line(skill.status_text, "a status text", MAX_STATUS_TEXT, empty=True)


def _read_skill(reader: DocumentReader, raw: object, agent: str, key: str) -> SkillInstance:
    body = reader.mapping(raw, key, set(_REQUIRED), set(_OPTIONAL))
    params = reader.mapping(body["params"], f"{key}.params", set(), None)
    bindings = reader.mapping(body.get("bindings", {}), f"{key}.bindings", set(), None)
    for name, marker in bindings.items():
        reader.text(marker, f"{key}.bindings.{name}")
    return SkillInstance(
        id=reader.text(body["id"], f"{key}.id"),
        agent=agent,
        skill=reader.text(body["skill"], f"{key}.skill"),
        label=reader.text(body.get("label", body["skill"]), f"{key}.label"),
        params=dict(params),
        bindings=dict(bindings),
        status=reader.enum(SkillStatus, body.get("status", "IDLE"), f"{key}.status"),
        transfer=reader.enum(Transfer, body.get("transfer", "NONE"), f"{key}.transfer"),
        resolution=reader.enum(Resolution, body.get("resolution", "NONE"), f"{key}.resolution"),
        attempt=reader.whole(body.get("attempt", 1), f"{key}.attempt", minimum=1),
        timeout=reader.number(body.get("timeout", 0.0), f"{key}.timeout", minimum=0.0),
        max_retries=reader.whole(body.get("max_retries", 0), f"{key}.max_retries", minimum=0),
        status_text=reader.text(body.get("status_text", ""), f"{key}.status_text", empty=True),
        started=reader.number(body.get("started", 0.0), f"{key}.started", minimum=0.0),
        finished=reader.number(body.get("finished", 0.0), f"{key}.finished", minimum=0.0),
    )


def _check_sections(reader: DocumentReader, task: list[SkillInstance], key: str) -> None:
    """Synchronized skills first, then uploading blueprint skills, then the rest.

    A robot runs its skills in order, so a skill that has started follows only
    settled ones (SUCCESS, or a FAILURE that was retried or skipped).
    """
    if {(s.status, s.transfer, s.resolution) for s in task} <= _BLUEPRINT:
        return  # a blueprint, nothing uploading: in order whatever the order
    rank_seen = 0
    unsettled = ""
    for i, skill in enumerate(task):
        if skill.status is not SkillStatus.IDLE:
            rank = 0
        else:
            rank = 1 if skill.transfer is Transfer.UPLOADING else 2
        if rank < rank_seen:
            reader.fail(f"{key}[{i}]", "a synchronized skill follows a blueprint skill")
        if (
            skill.transfer is Transfer.REMOVING
            and skill.status is not SkillStatus.IDLE_SYNCHRONIZED
        ):
            reader.fail(f"{key}[{i}].transfer", "only IDLE_SYNCHRONIZED skills can be removing")
        if skill.resolution is not Resolution.NONE and skill.status is not SkillStatus.FAILURE:
            reader.fail(f"{key}[{i}].resolution", "only a FAILURE can be retried or skipped")
        if skill.transfer is Transfer.UPLOADING and skill.status is not SkillStatus.IDLE:
            reader.fail(f"{key}[{i}].transfer", "only blueprint (IDLE) skills can be uploading")
        if skill.status.has_started and unsettled:
            reader.fail(
                f"{key}[{i}]",
                f"skill {skill.id!r} has started although the earlier {unsettled!r} is not done",
            )
        if not unsettled and not skill.is_settled:
            unsettled = skill.id
        rank_seen = max(rank_seen, rank)


def _read_barriers(
    reader: DocumentReader, raw: object, tasks: Mapping[str, list[SkillInstance]]
) -> dict[str, Barrier]:
    agent_of = {skill.id: agent for agent, task in tasks.items() for skill in task}
    barriers: dict[str, Barrier] = {}
    member_of: dict[str, str] = {}
    for i, entry in enumerate(reader.items(raw, "barriers")):
        key = f"barriers[{i}]"
        body = reader.mapping(entry, key, {"id", "skills"}, set())
        barrier_id = reader.text(body["id"], f"{key}.id")
        try:
            check_id(barrier_id, "a barrier id")
        except RosmcError as error:
            reader.fail(f"{key}.id", str(error))
        members = tuple(reader.text(s, f"{key}.skills") for s in reader.items(body["skills"], key))
        if barrier_id in barriers or barrier_id in agent_of:
            reader.fail(f"{key}.id", f"id {barrier_id!r} appears twice")
        if len(members) < 2:
            reader.fail(f"{key}.skills", "a barrier needs at least two skills")
        for skill_id in members:
            if skill_id not in agent_of:
                reader.fail(f"{key}.skills", f"refers to unknown skill {skill_id!r}")
            if skill_id in member_of:
                reader.fail(f"{key}.skills", f"skill {skill_id!r} is already in another barrier")
            member_of[skill_id] = barrier_id
        if len({agent_of[s] for s in members}) != len(members):
            reader.fail(f"{key}.skills", "barrier members must be on distinct agents")
        barriers[barrier_id] = Barrier(barrier_id, members)
    order = {agent: [s.id for s in task] for agent, task in tasks.items()}
    cycle = find_deadlock(order, [b.skill_ids for b in barriers.values()])
    if cycle:
        reader.fail("barriers", f"the barriers deadlock: {describe_cycle(cycle)}")
    return barriers
