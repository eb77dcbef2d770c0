"""Checking a parsed mission document and building the mission from it.

Every entry is checked against the library and the mission rules; the first problem
fails the whole document with one sentence naming the source, the key path and the
problem, and nothing is half-loaded. A task is read a column at a time where its
entries have the usual form (:mod:`.plain_skills`), else entry by entry
(:mod:`.skill_reading`), which either builds the same skills or says precisely what
is wrong.
"""

from __future__ import annotations

from collections.abc import Mapping
from operator import attrgetter

from ..documents.documents import DocumentReader
from ..errors import MissionFileError, RosmcError
from ..model.model import Barrier, Resolution, SkillInstance, SkillStatus, TaskMarker, Transfer
from ..model.state import MissionContent
from ..rules.barriers import describe_cycle, find_deadlock
from ..skills.library import Library
from ..skills.params import MarkerType, Pose
from ..validation import check_corners, check_id, check_skill_count
from .mission_text import MISSION_VERSION
from .plain_skills import PlainTask, read_plain, read_plain_task
from .shared_params import SharedParams
from .skill_reading import TaskReader as _TaskReader

_BLUEPRINT = {(SkillStatus.IDLE, Transfer.NONE, Resolution.NONE)}
_ID = attrgetter("id")
_SECTION = attrgetter("status", "transfer", "resolution")


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
    from ..rules.markers import check_marker

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
        check_skill_count(sum(len(e) for e in body.values() if isinstance(e, (list, PlainTask))))
    except RosmcError as error:
        reader.fail("tasks", str(error))
    seen: set[str] = set()
    shared = SharedParams(skills.params)  # alike parameters checked once, one dict for all
    for agent, entries in body.items():
        if agent not in tasks:
            reader.fail(f"tasks.{agent}", "names no dynamic agent of the library")
        task = tasks[agent]
        if isinstance(entries, PlainTask):
            plain = read_plain_task(entries, agent, skills.spec, skills.params)
            if plain is None:  # read one by one, to say what is wrong
                read, entries = entries, entries.entries()
                if consume:
                    read.clear()
        else:
            plain = read_plain(entries, agent, skills.spec, shared)
        if plain is not None:
            ids = set(map(_ID, plain))
            # else read one by one, to name the id given twice
            if len(ids) == len(plain) and seen.isdisjoint(ids):
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


def _check_sections(reader: DocumentReader, task: list[SkillInstance], key: str) -> None:
    """Synchronized skills first, then uploading blueprint skills, then the rest.

    A robot runs its skills in order, so a skill that has started follows only
    settled ones (SUCCESS, or a FAILURE that was retried or skipped).
    """
    if set(map(_SECTION, task)) <= _BLUEPRINT:
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
    agent_of: dict[str, str] = {}
    for agent, task in tasks.items():
        agent_of.update(dict.fromkeys(map(_ID, task), agent))
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
    order = {agent: list(map(_ID, task)) for agent, task in tasks.items()}
    cycle = find_deadlock(order, [b.skill_ids for b in barriers.values()])
    if cycle:
        reader.fail("barriers", f"the barriers deadlock: {describe_cycle(cycle)}")
    return barriers
