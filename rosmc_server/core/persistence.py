"""Mission files: versioned YAML, read with ``yaml.safe_load`` only.

A file holds the mission's tasks, barriers, task markers, revision and the
name of its library. Loading checks everything against the library and the
mission rules and fails with one sentence naming the file and the problem;
nothing is half-loaded. Python object tags are refused, never executed, and
so are YAML aliases that expand a document beyond reason.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import replace
from pathlib import Path
from typing import Any

import yaml

from .barriers import describe_cycle, find_deadlock
from .documents import DocumentReader, DuplicateKeyError, SafeDumper, load_yaml, yaml_problem
from .durable import write_durably
from .errors import MissionFileError, RosmcError
from .library import Library
from .model import Barrier, Resolution, SkillInstance, SkillStatus, TaskMarker, Transfer
from .params import MarkerType, Pose, value_to_data
from .state import MissionContent
from .validation import check_id

MISSION_VERSION = 1


def mission_to_dict(content: MissionContent, revision: int) -> dict[str, Any]:
    """The mission as plain data, ready for ``yaml.safe_dump``."""
    return {
        "rosmc_mission": MISSION_VERSION,
        "library": content.library,
        "revision": revision,
        "tasks": {
            agent: [_skill_to_dict(skill) for skill in task]
            for agent, task in content.tasks.items()
        },
        "barriers": [{"id": b.id, "skills": list(b.skill_ids)} for b in content.barriers.values()],
        "markers": [_marker_to_dict(m) for m in content.markers.values()],
    }


class _PlainDumper(SafeDumper):  # type: ignore[misc, valid-type]
    """A safe dumper that writes shared values out in full instead of as anchors and aliases.

    A retried skill shares its parameter values with the original; aliases would
    make the file harder to read and not come back identical after a load.
    """

    def ignore_aliases(self, data: Any) -> bool:
        return True


def dump_mission(content: MissionContent, revision: int) -> str:
    """The mission as a YAML document."""
    return yaml.dump(
        mission_to_dict(content, revision), Dumper=_PlainDumper, sort_keys=False, width=100
    )


def save_mission(path: str | Path, content: MissionContent, revision: int) -> None:
    """Write the mission to ``path`` atomically and durably (see :func:`write_durably`)."""
    try:
        write_durably(Path(path), dump_mission(content, revision))
    except OSError as error:
        raise MissionFileError(f"{path}: cannot write the mission ({error.strerror})") from error


def load_mission(path: str | Path, library: Library) -> tuple[MissionContent, int]:
    """Read and check a mission file; return its content and revision."""
    try:
        text = Path(path).read_text(encoding="utf-8")
    except OSError as error:
        raise MissionFileError(f"{path}: cannot read the mission ({error.strerror})") from error
    except UnicodeDecodeError as error:
        problem = f"the file is not UTF-8 text (byte {error.start})"
        raise MissionFileError(f"{path}: {problem}") from error
    return parse_mission(text, library, str(path))


def parse_mission(text: str, library: Library, source: str) -> tuple[MissionContent, int]:
    """Parse and check a mission document; return its content and revision."""
    try:
        data = load_yaml(text)
    except DuplicateKeyError as error:
        raise MissionFileError(f"{source}: not valid YAML ({yaml_problem(error)})") from error
    except yaml.constructor.ConstructorError as error:
        raise MissionFileError(
            f"{source}: refused a YAML tag that is not plain data ({error.problem})"
        ) from error
    except yaml.YAMLError as error:
        raise MissionFileError(f"{source}: not valid YAML ({yaml_problem(error)})") from error
    _refuse_alias_bombs(data, len(text), source)
    return mission_from_dict(data, library, source)


def _refuse_alias_bombs(data: object, length: int, source: str) -> None:
    """Refuse a document whose YAML aliases expand it far beyond its own size.

    An alias refers to a value written once, but checking copies it wherever it
    is used, so a few hundred bytes of nested aliases ("billion laughs") would
    take hours to load. Ordinary sharing (what yaml.safe_dump writes for repeated
    values) stays well within the allowance.
    """
    allowance = 100_000 + 20 * length
    pending, count = [data], 0
    while pending:
        item = pending.pop()
        count += 1
        if count > allowance:
            raise MissionFileError(
                f"{source}: its YAML aliases expand it to more than {allowance} values"
            )
        if isinstance(item, dict):
            pending.extend(item.values())
        elif isinstance(item, list):
            pending.extend(item)


def mission_from_dict(
    data: object, library: Library, source: str = "<mission>"
) -> tuple[MissionContent, int]:
    """Build and check a mission from plain data."""
    reader = DocumentReader(source, MissionFileError)
    if isinstance(data, dict) and "rosmc_mission" in data:
        _check_version(reader, data["rosmc_mission"])  # before anything a new version may change
    top = reader.mapping(
        data,
        "",
        {"rosmc_mission", "library", "revision", "tasks"},
        {"barriers", "markers"},
    )
    version = top["rosmc_mission"]
    if isinstance(version, bool) or version != MISSION_VERSION:
        reader.fail(
            "rosmc_mission",
            f"unsupported mission file version {top['rosmc_mission']!r}",
        )
    if top["library"] != library.name:
        reader.fail("library", f"written for library {top['library']!r}, not {library.name!r}")
    revision = top["revision"]
    if isinstance(revision, bool) or not isinstance(revision, int) or revision < 0:
        reader.fail("revision", f"must be a whole number >= 0, got {revision!r}")
    markers = _read_markers(reader, top.get("markers", []))
    tasks = _read_tasks(reader, top["tasks"], library, markers)
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


def _read_tasks(
    reader: DocumentReader,
    raw: object,
    library: Library,
    markers: Mapping[str, TaskMarker],
) -> dict[str, list[SkillInstance]]:
    from .editing import bound_values, check_params

    body = reader.mapping(raw, "tasks", set(), None)
    tasks: dict[str, list[SkillInstance]] = {agent: [] for agent in library.dynamic_agents}
    seen: set[str] = set()
    for agent, entries in body.items():
        if agent not in tasks:
            reader.fail(f"tasks.{agent}", "names no dynamic agent of the library")
        for i, entry in enumerate(reader.items(entries, f"tasks.{agent}")):
            key = f"tasks.{agent}[{i}]"
            skill = _read_skill(reader, entry, agent, key)
            try:
                check_loaded_skill(skill)
            except RosmcError as error:
                reader.fail(key, str(error))
            if skill.id in seen:
                reader.fail(f"{key}.id", f"skill id {skill.id!r} appears twice")
            seen.add(skill.id)
            try:
                spec = library.skill(agent, skill.skill)
                skill = replace(skill, params=check_params(spec, skill.params))
                bound_values(lambda name: _marker(markers, name), spec, skill.bindings)
            except RosmcError as error:
                reader.fail(key, str(error))
            missing = sorted({p.name for p in spec.parameters} - set(skill.params))
            if missing:
                reader.fail(f"{key}.params", f"is missing {', '.join(missing)}")
            tasks[agent].append(skill)
        _check_sections(reader, tasks[agent], f"tasks.{agent}")
    return tasks


def check_loaded_skill(skill: SkillInstance) -> None:
    """The checks an added or edited skill passes, for a skill read from a file."""
    from .editing import check_label, check_retries, check_timeout
    from .validation import MAX_ATTEMPT, MAX_STATUS_TEXT, check_one_line, check_whole

    check_id(skill.id)
    check_label(skill.label, None)
    check_timeout(skill.timeout)
    check_retries(skill.max_retries)
    check_whole(skill.attempt, "an attempt", 1, MAX_ATTEMPT)
    check_one_line(skill.status_text, "a status text", MAX_STATUS_TEXT, empty=True)


def _marker(markers: Mapping[str, TaskMarker], name: str) -> TaskMarker:
    if name not in markers:
        raise MissionFileError(f"binds marker {name!r}, which the file does not define")
    return markers[name]


def _read_skill(reader: DocumentReader, raw: object, agent: str, key: str) -> SkillInstance:
    body = reader.mapping(
        raw,
        key,
        {"id", "skill", "params"},
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
        },
    )
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


def _skill_to_dict(skill: SkillInstance) -> dict[str, Any]:
    data: dict[str, Any] = {
        "id": skill.id,
        "skill": skill.skill,
        "label": skill.label,
        "params": {name: value_to_data(value) for name, value in skill.params.items()},
        "status": skill.status.name,
    }
    if skill.bindings:
        data["bindings"] = dict(skill.bindings)
    optional = {
        "transfer": (skill.transfer.name, "NONE"),
        "resolution": (skill.resolution.name, "NONE"),
        "attempt": (skill.attempt, 1),
        "timeout": (skill.timeout, 0.0),
        "max_retries": (skill.max_retries, 0),
        "status_text": (skill.status_text, ""),
        "started": (skill.started, 0.0),
        "finished": (skill.finished, 0.0),
    }
    data.update({key: value for key, (value, default) in optional.items() if value != default})
    return data


def _marker_to_dict(marker: TaskMarker) -> dict[str, Any]:
    data: dict[str, Any] = {
        "name": marker.name,
        "type": marker.type.name,
        "pose": marker.pose.to_dict(),
    }
    if marker.vertices:
        data["vertices"] = [v.to_dict() for v in marker.vertices]
    return data
