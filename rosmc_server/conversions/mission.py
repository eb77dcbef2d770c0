"""The one boundary between ROS messages and the mission core.

``x_to_msg`` builds a ``rosmc`` message from a core object; ``x_from_msg``
builds the core object back (raising InvalidRequest for malformed input, so
service handlers can answer with an error). Round trips are exact.
"""

from __future__ import annotations

import json
from collections.abc import Callable, Iterable
from typing import Any

import genpy
import rosmc.msg as wire

from ..core import (
    Barrier,
    Change,
    EventKind,
    InvalidRequest,
    Library,
    MarkerType,
    MissionContent,
    MissionEvent,
    ParameterSpec,
    ParamType,
    PlacedSkill,
    Pose,
    Resolution,
    SkillInstance,
    SkillStatus,
    TaskMarker,
    Transfer,
    Value,
)

# Deeper LIST/DICT values are refused: the core checks them and the YAML mission files
# write them recursively, which fails a few hundred levels down.
MAX_JSON_NESTING = 32


def time_to_msg(seconds: float) -> genpy.Time:
    """Seconds since the epoch as a ROS time (0 stays 0)."""
    return genpy.Time.from_sec(max(0.0, seconds))


def pose_to_msg(pose: Pose) -> wire.Pose6D:
    """A core pose as ``rosmc/Pose6D``."""
    return wire.Pose6D(pose.x, pose.y, pose.z, pose.roll, pose.pitch, pose.yaw)


def pose_from_msg(msg: wire.Pose6D) -> Pose:
    """``rosmc/Pose6D`` as a core pose."""
    return Pose(msg.x, msg.y, msg.z, msg.roll, msg.pitch, msg.yaw)


def value_type(value: Value) -> ParamType:
    """The wire type of a core value (core values are normalized, so this is exact)."""
    if isinstance(value, bool):
        return ParamType.BOOL
    if isinstance(value, int):
        return ParamType.INT
    if isinstance(value, float):
        return ParamType.FLOAT
    if isinstance(value, str):
        return ParamType.STRING
    if isinstance(value, list):
        return ParamType.LIST
    if isinstance(value, dict):
        return ParamType.DICT
    return ParamType.POSE


def param_to_msg(name: str, value: Value, marker: str = "") -> wire.ParameterValue:
    """One named value as ``rosmc/ParameterValue``."""
    msg = wire.ParameterValue(name=name, marker=marker)
    ptype = value_type(value)
    msg.type = int(ptype)
    if ptype is ParamType.BOOL:
        msg.bool_value = value
    elif ptype is ParamType.INT:
        msg.int_value = value
    elif ptype is ParamType.FLOAT:
        msg.float_value = value
    elif ptype is ParamType.STRING:
        msg.string_value = value
    elif ptype in (ParamType.LIST, ParamType.DICT):
        msg.json_value = json.dumps(value, separators=(",", ":"))
    else:
        assert isinstance(value, Pose)
        msg.pose_value = pose_to_msg(value)
    return msg


def param_from_msg(msg: wire.ParameterValue) -> tuple[str, object]:
    """The name and raw value of a ``rosmc/ParameterValue`` (checked later by the core)."""
    name = msg.name
    if not name:
        raise InvalidRequest("a parameter has an empty name")
    try:
        ptype = ParamType(msg.type)
    except ValueError:
        raise InvalidRequest(f"parameter '{name}' has unknown type number {msg.type}") from None
    if ptype is ParamType.BOOL:
        return name, bool(msg.bool_value)
    if ptype is ParamType.INT:
        return name, int(msg.int_value)
    if ptype is ParamType.FLOAT:
        return name, float(msg.float_value)
    if ptype is ParamType.STRING:
        return name, msg.string_value
    if ptype is ParamType.POSE:
        return name, pose_from_msg(msg.pose_value)
    try:
        data = json.loads(msg.json_value)
    except (ValueError, RecursionError):
        raise InvalidRequest(f"parameter '{name}' does not hold valid JSON") from None
    expected = list if ptype is ParamType.LIST else dict
    if not isinstance(data, expected):
        raise InvalidRequest(f"parameter '{name}' must hold a JSON {expected.__name__}")
    if _nesting(data) > MAX_JSON_NESTING:
        raise InvalidRequest(
            f"parameter '{name}' nests its JSON deeper than {MAX_JSON_NESTING} levels"
        )
    return name, data


def _nesting(data: object) -> int:
    """How deep lists and dicts nest in ``data`` (without recursion: the data may be deep)."""
    deepest = 0
    stack = [(data, 1)]
    while stack:
        item, depth = stack.pop()
        if isinstance(item, dict):
            item = list(item.values())
        if isinstance(item, list):
            deepest = max(deepest, depth)
            stack.extend((child, depth + 1) for child in item)
    return deepest


def params_from_msgs(
    msgs: Iterable[wire.ParameterValue],
) -> tuple[dict[str, object], dict[str, str]]:
    """Split parameter messages into values and marker bindings; names must be unique.

    A bound parameter takes its value from its marker, so only its name and marker
    are read: the value fields of a binding may be left empty.
    """
    values: dict[str, object] = {}
    bindings: dict[str, str] = {}
    for msg in msgs:
        if msg.marker:
            name = msg.name
            if not name:
                raise InvalidRequest("a parameter has an empty name")
        else:
            name, value = param_from_msg(msg)
        if name in values or name in bindings:
            raise InvalidRequest(f"parameter '{name}' is given twice")
        if msg.marker:
            bindings[name] = msg.marker
        else:
            values[name] = value
    return values, bindings


def skill_to_msg(skill: SkillInstance) -> wire.Skill:
    """A skill instance as ``rosmc/Skill``."""
    return wire.Skill(
        id=skill.id,
        agent=skill.agent,
        skill=skill.skill,
        label=skill.label,
        parameters=[
            param_to_msg(name, value, skill.bindings.get(name, ""))
            for name, value in skill.params.items()
        ],
        status=wire.SkillStatus(int(skill.status)),
        transfer=int(skill.transfer),
        resolution=int(skill.resolution),
        attempt=skill.attempt,
        timeout=skill.timeout,
        max_retries=skill.max_retries,
        status_text=skill.status_text,
        started=skill.started,
        finished=skill.finished,
    )


def skill_from_msg(msg: wire.Skill) -> SkillInstance:
    """``rosmc/Skill`` as a skill instance (values as sent; the core checks them on use)."""
    params: dict[str, Any] = {}
    bindings: dict[str, str] = {}
    for param in msg.parameters:
        name, value = param_from_msg(param)
        params[name] = value
        if param.marker:
            bindings[name] = param.marker
    return SkillInstance(
        id=msg.id,
        agent=msg.agent,
        skill=msg.skill,
        label=msg.label,
        params=params,
        bindings=bindings,
        status=_enum(SkillStatus, msg.status.value, "status"),
        transfer=_enum(Transfer, msg.transfer, "transfer"),
        resolution=_enum(Resolution, msg.resolution, "resolution"),
        attempt=msg.attempt,
        timeout=msg.timeout,
        max_retries=msg.max_retries,
        status_text=msg.status_text,
        started=msg.started,
        finished=msg.finished,
    )


def _enum(kind: Any, number: int, what: str) -> Any:
    try:
        return kind(number)
    except ValueError:
        raise InvalidRequest(f"unknown {what} number {number}") from None


def barrier_to_msg(barrier: Barrier, agent_of: Callable[[str], str]) -> wire.Barrier:
    """A barrier as ``rosmc/Barrier`` (with each member's agent)."""
    return wire.Barrier(
        id=barrier.id,
        skill_ids=list(barrier.skill_ids),
        agents=[agent_of(skill_id) for skill_id in barrier.skill_ids],
    )


def barrier_from_msg(msg: wire.Barrier) -> Barrier:
    """``rosmc/Barrier`` as a core barrier."""
    return Barrier(msg.id, tuple(msg.skill_ids))


def marker_to_msg(marker: TaskMarker) -> wire.TaskMarker:
    """A task marker as ``rosmc/TaskMarker``."""
    return wire.TaskMarker(
        name=marker.name,
        type=int(marker.type),
        pose=pose_to_msg(marker.pose),
        vertices=[pose_to_msg(v) for v in marker.vertices],
    )


def marker_from_msg(msg: wire.TaskMarker) -> TaskMarker:
    """``rosmc/TaskMarker`` as a core marker (shape checked by the core)."""
    return TaskMarker(
        msg.name,
        _enum(MarkerType, msg.type, "marker type"),
        pose_from_msg(msg.pose),
        tuple(pose_from_msg(v) for v in msg.vertices),
    )


def mission_to_msg(
    content: MissionContent,
    revision: int,
    stamp: float,
    skill_msg: Callable[[SkillInstance], wire.Skill] = skill_to_msg,
) -> wire.Mission:
    """A full snapshot as ``rosmc/Mission`` (``skill_msg`` converts each skill)."""
    agent_of = {skill.id: agent for agent, task in content.tasks.items() for skill in task}
    return wire.Mission(
        revision=revision,
        stamp=time_to_msg(stamp),
        library=content.library,
        tasks=[
            wire.AgentTask(agent=agent, skills=[skill_msg(s) for s in task])
            for agent, task in content.tasks.items()
        ],
        barriers=[barrier_to_msg(b, agent_of.__getitem__) for b in content.barriers.values()],
        markers=[marker_to_msg(m) for m in content.markers.values()],
    )


class SnapshotConverter:
    """Builds mission snapshots, converting only the skills changed since the last one.

    Skill instances are frozen and replaced by a new instance on every change, so an
    instance still in the mission converts to the message it converted to last time.
    Converting all 10,000 skills of a large mission takes a third of a second of
    Python; reusing the unchanged ones makes a snapshot cheap. The skill messages are
    shared between snapshots, so a snapshot must not be modified. Safe to call from
    several threads at once.
    """

    def __init__(self) -> None:
        self._cache: dict[int, tuple[SkillInstance, wire.Skill]] = {}

    def mission_to_msg(self, content: MissionContent, revision: int, stamp: float) -> wire.Mission:
        """A full snapshot as ``rosmc/Mission``."""
        previous = self._cache
        current: dict[int, tuple[SkillInstance, wire.Skill]] = {}

        def convert(skill: SkillInstance) -> wire.Skill:
            entry = previous.get(id(skill))
            if entry is None or entry[0] is not skill:  # the entry holds the skill: ids stay
                entry = (skill, skill_to_msg(skill))
            current[id(skill)] = entry
            return entry[1]

        msg = mission_to_msg(content, revision, stamp, convert)
        self._cache = current
        return msg


def mission_from_msg(msg: wire.Mission) -> tuple[MissionContent, int]:
    """``rosmc/Mission`` as core content and revision."""
    tasks = {task.agent: [skill_from_msg(s) for s in task.skills] for task in msg.tasks}
    barriers = {b.id: barrier_from_msg(b) for b in msg.barriers}
    markers = {m.name: marker_from_msg(m) for m in msg.markers}
    return MissionContent(msg.library, tasks, barriers, markers), msg.revision


def event_to_msg(event: MissionEvent, agent_of: Callable[[str], str]) -> wire.MissionEvent:
    """An event as ``rosmc/MissionEvent`` (a replacement travels without content)."""
    change = event.change
    return wire.MissionEvent(
        revision=event.revision,
        stamp=time_to_msg(event.stamp),
        kind=int(event.kind),
        agent=event.agent,
        summary=event.summary,
        put_skills=[
            wire.PlacedSkill(index=p.index, skill=skill_to_msg(p.skill)) for p in change.put_skills
        ],
        removed_skill_ids=list(change.removed_skill_ids),
        order_agent=change.order_agent,
        blueprint_order=list(change.blueprint_order),
        put_barriers=[barrier_to_msg(b, agent_of) for b in change.put_barriers],
        removed_barrier_ids=list(change.removed_barrier_ids),
        put_markers=[marker_to_msg(m) for m in change.put_markers],
        removed_marker_names=list(change.removed_marker_names),
    )


def event_from_msg(msg: wire.MissionEvent) -> MissionEvent:
    """``rosmc/MissionEvent`` as a core event (a replacement has no content)."""
    change = Change(
        put_skills=tuple(PlacedSkill(p.index, skill_from_msg(p.skill)) for p in msg.put_skills),
        removed_skill_ids=tuple(msg.removed_skill_ids),
        order_agent=msg.order_agent,
        blueprint_order=tuple(msg.blueprint_order),
        put_barriers=tuple(barrier_from_msg(b) for b in msg.put_barriers),
        removed_barrier_ids=tuple(msg.removed_barrier_ids),
        put_markers=tuple(marker_from_msg(m) for m in msg.put_markers),
        removed_marker_names=tuple(msg.removed_marker_names),
    )
    return MissionEvent(
        msg.revision,
        _enum(EventKind, msg.kind, "event kind"),
        msg.agent,
        msg.summary,
        msg.stamp.to_sec(),
        change,
    )


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
            wire.SkillSet(model=model, skills=[_skill_spec_to_msg(s) for s in skills.values()])
            for model, skills in library.models.items()
        ],
    )


def _skill_spec_to_msg(spec: Any) -> wire.SkillSpec:
    return wire.SkillSpec(
        name=spec.name,
        description=spec.description,
        parameters=[parameter_spec_to_msg(p) for p in spec.parameters],
        estimated_duration=spec.estimated_duration,
    )
