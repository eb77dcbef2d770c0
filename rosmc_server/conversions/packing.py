"""Mission snapshots as ROS 1 wire bytes, built incrementally and serialized once.

Part of :mod:`rosmc_server.conversions`. A snapshot of 10,000 skills is megabytes; building
it as genpy messages and serializing those costs a third of a second per snapshot.
:class:`SnapshotPacker` keeps each skill's serialized bytes, keyed by the (frozen) core
skill instance, so a snapshot after a change serializes only the changed skills and
joins the rest. The result is a :class:`PackedMission`: a ``rosmc/Mission`` whose
``serialize`` writes those bytes, which rospy publishes, answers a service with
(:class:`PackedGetMissionResponse`) or the journal records, like any message.

:func:`skill_bytes` writes a skill's wire bytes directly (about five times faster than
through a genpy message); it is used only while ``rosmc/Skill`` is the definition it was written
for (its md5sum), and a test checks it against genpy's bytes for random skills.
"""

from __future__ import annotations

import io
import json
import operator
import struct
import threading
from array import array
from collections.abc import Iterable, Sequence
from typing import Any

import genpy
import rosmc.msg as wire
import rosmc.srv as srv

from ..core import MissionContent, ParamType, Pose, SkillInstance, Value
from .body_writer import BodyWriter, PackedBody, PackedTask
from .mission import barrier_to_msg, marker_to_msg, skill_to_msg
from .values import time_to_msg, value_type

# The rosmc/Skill definition skill_bytes writes (with its nested types).
PACKED_SKILL_MD5 = "04b969e0a9ae2f890680d46e621a0723"

_COUNT = struct.Struct("<I")
_HEADER = struct.Struct("<Q2I")  # revision, stamp
_PARAM_NUMBERS = struct.Struct("<2Bqd")  # type, bool_value, int_value, float_value
_POSE = struct.Struct("<6d")
_NO_POSE = _POSE.pack(0.0, 0.0, 0.0, 0.0, 0.0, 0.0)
_SKILL_NUMBERS = struct.Struct("<3BIdI")  # status, transfer, resolution, attempt, timeout, ...
_TIMES = struct.Struct("<2d")  # started, finished
_EMPTY = _COUNT.pack(0)  # an empty string or array
_NO_TEXT_NO_POSE = _EMPTY + _EMPTY + _NO_POSE  # a number parameter's unused fields
_POSE_HEAD = _PARAM_NUMBERS.pack(ParamType.POSE, False, 0, 0.0) + _EMPTY + _EMPTY
_STRING_HEAD = _PARAM_NUMBERS.pack(ParamType.STRING, False, 0, 0.0)


def string_bytes(text: str) -> bytes:
    """The wire bytes of a ROS ``string``."""
    if not text:
        return _EMPTY
    data = text.encode("utf-8")
    return _COUNT.pack(len(data)) + data


def _param_body(value: Value) -> bytes:
    """A ``rosmc/ParameterValue`` after its name, before its marker (as param_to_msg fills it)."""
    kind = type(value)  # the common types first, without the generic dispatch
    if kind is float:
        return _PARAM_NUMBERS.pack(ParamType.FLOAT, False, 0, value) + _NO_TEXT_NO_POSE
    if kind is Pose:
        pose = value
        assert isinstance(pose, Pose)
        numbers = _POSE.pack(pose.x, pose.y, pose.z, pose.roll, pose.pitch, pose.yaw)
        return _POSE_HEAD + numbers
    if kind is int:
        return _PARAM_NUMBERS.pack(ParamType.INT, False, value, 0.0) + _NO_TEXT_NO_POSE
    if kind is str:
        assert isinstance(value, str)
        return _STRING_HEAD + string_bytes(value) + _EMPTY + _NO_POSE
    ptype = value_type(value)
    return b"".join(
        (
            _PARAM_NUMBERS.pack(ptype, value if ptype is ParamType.BOOL else False, 0, 0.0),
            _EMPTY,
            string_bytes(json.dumps(value, separators=(",", ":")))
            if ptype in (ParamType.LIST, ParamType.DICT)
            else _EMPTY,
            _NO_POSE,
        )
    )


def skill_bytes(
    skill: SkillInstance,
    names: dict[str, bytes] | None = None,
    shared: dict[int, tuple[Any, Any, bytes]] | None = None,
) -> bytes:
    """The ROS 1 wire bytes of ``skill_to_msg(skill)``.

    ``names`` keeps the encoded agent, skill and parameter names between calls (a library
    has few of them); pass the same dict to every call. ``shared`` keeps the bytes of
    each parameters dict written, for skills that share one (a loaded mission's alike
    parameters, see :mod:`~rosmc_server.core.files.shared_params`): pass one dict to the calls
    for one mission.
    """
    if wire.Skill._md5sum != PACKED_SKILL_MD5:  # the definition changed: go through genpy
        return serialized(skill_to_msg(skill))
    if names is None:
        names = {}
    params, bindings = skill.params, skill.bindings
    found = shared.get(id(params)) if shared is not None else None
    if found is not None and found[0] is params and found[1] is bindings:
        block = found[2]
    else:
        block = _params_bytes(params, bindings, names)
        if shared is not None:
            shared[id(params)] = (params, bindings, block)  # kept alive: ids stay theirs
    return b"".join(
        (
            string_bytes(skill.id),
            names.get(skill.agent) or names.setdefault(skill.agent, string_bytes(skill.agent)),
            names.get(skill.skill) or names.setdefault(skill.skill, string_bytes(skill.skill)),
            string_bytes(skill.label),
            block,
            _SKILL_NUMBERS.pack(
                skill.status,
                skill.transfer,
                skill.resolution,
                skill.attempt,
                skill.timeout,
                skill.max_retries,
            ),
            string_bytes(skill.status_text),
            _TIMES.pack(skill.started, skill.finished),
        )
    )


def _params_bytes(params: Any, bindings: Any, names: dict[str, bytes]) -> bytes:
    """The ``rosmc/ParameterValue[]`` of a skill's parameters and marker bindings."""
    parts = [_COUNT.pack(len(params))]
    for name, value in params.items():
        parts += (
            names.get(name) or names.setdefault(name, string_bytes(name)),
            _param_body(value),
            string_bytes(bindings[name]) if name in bindings else _EMPTY,
        )
    return b"".join(parts)


def serialized(msg: Any) -> bytes:
    """The ROS 1 wire bytes of a genpy message."""
    buffer = io.BytesIO()
    msg.serialize(buffer)
    return buffer.getvalue()


def _array(items: Iterable[Any]) -> bytes:
    """A ROS 1 array of messages: its length, then each message's bytes."""
    parts = [serialized(item) for item in items]
    return _COUNT.pack(len(parts)) + b"".join(parts)


class PackedMission(wire.Mission):  # type: ignore[misc]
    """A ``rosmc/Mission`` that serializes as given bytes (shared, never copied).

    Only ``revision`` and ``stamp`` are set as fields; the library, tasks, barriers and
    markers are in the bytes. Deserialize the bytes (:meth:`unpacked`) to read them.
    """

    def __init__(self, revision: int, stamp: genpy.Time, body: bytes) -> None:
        super().__init__(revision=revision, stamp=stamp)
        self.body = body

    def serialize(self, buff: Any) -> None:
        """Write the message's wire bytes to ``buff``."""
        buff.write(_HEADER.pack(self.revision, self.stamp.secs, self.stamp.nsecs))
        buff.write(self.body)

    def unpacked(self) -> wire.Mission:
        """The snapshot as an ordinary message."""
        return wire.Mission().deserialize(serialized(self))

    def __str__(self) -> str:
        return f"rosmc/Mission revision {self.revision} ({len(self.body)} bytes, packed)"

    __repr__ = __str__


class PackedGetMissionResponse(srv.GetMissionResponse):  # type: ignore[misc]
    """A ``rosmc/GetMission`` answer holding a :class:`PackedMission`."""

    def __init__(self, mission: PackedMission, journal_alert: str = "", epoch: str = "") -> None:
        super().__init__(mission=mission, journal_alert=journal_alert, epoch=epoch)

    def serialize(self, buff: Any) -> None:
        """Write the message's wire bytes to ``buff``: the packed mission, alert and epoch."""
        self.mission.serialize(buff)
        buff.write(string_bytes(self.journal_alert))
        buff.write(string_bytes(self.epoch))


class SnapshotPacker:
    """Builds packed mission snapshots, serializing only the skills changed since the last.

    Skill instances are frozen and replaced by a new instance on every change, so an
    instance still in the mission has the bytes it had last time: a task that holds the
    very instances of last time is reused whole (checked in C, position by position), and
    a changed task reuses the bytes of each skill still there. Those bytes are kept once,
    in the last snapshot's body. :meth:`prepare` serializes a mission ahead (one about to
    be loaded, outside the server's lock): its first snapshot is then the prepared body
    itself. Safe to call from several threads at once.
    """

    def __init__(self) -> None:
        self._last = PackedBody(b"", {})  # the last snapshot's
        self._prepared = PackedBody(b"", {})  # the last prepare's
        self._names: dict[str, bytes] = {}  # agent, skill and parameter names, encoded
        self._lock = threading.Lock()

    def prepare(self, content: MissionContent) -> None:
        """Serialize ``content`` now, so that the next snapshot holding its skills is quick.

        Kept until a snapshot takes it over (a snapshot built meanwhile of the old mission
        does not drop it) or the next call.
        """
        with self._lock:
            self._prepared = PackedBody(b"", {})  # the previous one is not kept beside the new one
        shared: dict[int, tuple[Any, Any, bytes]] = {}  # alike parameters written once
        prepared = self._build(content, {}, {}, shared)
        with self._lock:
            self._prepared = prepared

    def forget(self) -> None:
        """Drop the last snapshot's bytes (the next one serializes every skill afresh)."""
        with self._lock:
            self._last = PackedBody(b"", {})

    def body(self, content: MissionContent) -> bytes:
        """The wire bytes of a ``rosmc/Mission`` of ``content`` after its revision and stamp."""
        with self._lock:
            previous, prepared = self._last, self._prepared
        if _is_prepared(content, prepared):
            built = prepared  # a loaded mission's first snapshot: the bytes made ahead
        else:
            built = self._build(content, previous.tasks, prepared.tasks, None)
        with self._lock:
            self._last = built
            taken = [a for a, p in built.tasks.items() if p.data is prepared.data]
            taken += built.taken
            if taken and self._prepared is prepared:
                # A task this snapshot took over lives on in it; the others wait (a snapshot
                # of the old mission may come first).
                rest = {a: p for a, p in prepared.tasks.items() if a not in taken}
                self._prepared = PackedBody(prepared.data if rest else b"", rest)
        return built.data

    def pack(self, content: MissionContent, revision: int, stamp: float) -> PackedMission:
        """A packed snapshot of ``content`` at ``revision``."""
        return PackedMission(revision, time_to_msg(stamp), self.body(content))

    def _build(
        self,
        content: MissionContent,
        previous: dict[str, PackedTask],
        prepared: dict[str, PackedTask],
        shared: dict[int, tuple[Any, Any, bytes]] | None,
    ) -> PackedBody:
        """The body of ``content``, reusing the bytes of skills packed before."""
        writer = BodyWriter()
        writer.write(_head(content))
        placed: list[tuple[str, list[SkillInstance], int, array[int]]] = []
        taken: list[str] = []  # tasks taken whole from ``prepared``
        for agent, task in content.tasks.items():
            writer.write(_task_head(agent, task))
            start = writer.tell()
            sources = [p for p in (previous.get(agent), prepared.get(agent)) if p is not None]
            whole = next((p for p in sources if _same_instances(p.skills, task)), None)
            if whole is not None:
                writer.reuse(whole.data, *whole.span(0, len(task)))
                placed.append((agent, whole.skills, start, whole.ends))
                if whole is prepared.get(agent):
                    taken.append(agent)
            else:
                ends = self._pack_task(task, sources, writer, shared)
                placed.append((agent, list(task), start, ends))
        writer.write(_tail(content))
        data = writer.value()
        tasks = {a: PackedTask(skills, data, start, ends) for a, skills, start, ends in placed}
        return PackedBody(data, tasks, tuple(taken))

    def _pack_task(
        self,
        task: Sequence[SkillInstance],
        sources: list[PackedTask],
        writer: BodyWriter,
        shared: dict[int, tuple[Any, Any, bytes]] | None,
    ) -> array[int]:
        """Write ``task``, reusing the bytes of each skill ``sources`` hold (packed before);
        return where each skill's bytes end.

        A skill is looked for where it was, or one place off (one inserted, deleted or
        moved before it); only a task that changed in more than a few places (a range
        deleted, many moves) looks skills up by identity.
        """
        start = writer.tell()
        ends: array[int] = array("Q")
        misses, index, count = 0, 0, len(task)
        moved: dict[int, tuple[SkillInstance, PackedTask, int]] | None = None
        while index < count:
            skill = task[index]
            found = _near(sources, index, skill)
            if found is None:
                misses += 1
                if moved is None and misses > _FEW_MISSES:
                    moved = {
                        id(s): (s, source, at)
                        for source in sources
                        for at, s in enumerate(source.skills)
                    }
                entry = moved.get(id(skill)) if moved else None
                found = (entry[1], entry[2]) if entry is not None and entry[0] is skill else None
            if found is None:
                writer.write(skill_bytes(skill, self._names, shared))
                ends.append(writer.tell() - start)
                index += 1
                continue
            source, at = found
            run = _run_length(source.skills, at, task, index)
            begin, end = source.span(at, at + run)
            shift = writer.tell() - start - (begin - source.start)  # old place to new
            writer.reuse(source.data, begin, end)
            ends.extend(map(shift.__add__, source.ends[at : at + run]))
            index += run
        return ends


def _run_length(old: list[SkillInstance], at: int, new: Sequence[SkillInstance], index: int) -> int:
    """How many skills from ``new[index]`` on are the very skills from ``old[at]`` on."""
    limit = min(len(old) - at, len(new) - index)
    run = 1
    while run < limit and old[at + run] is new[index + run]:
        run += 1
    return run


_FEW_MISSES = 8  # skills of a task not found near their place before it looks them up by id


def _near(
    sources: list[PackedTask], index: int, skill: SkillInstance
) -> tuple[PackedTask, int] | None:
    """Where a source holds ``skill``: at ``index`` or one place off."""
    for source in sources:
        skills = source.skills
        for at in (index, index + 1, index - 1):
            if 0 <= at < len(skills) and skills[at] is skill:
                return source, at
    return None


def _same_instances(old: list[SkillInstance], new: Sequence[SkillInstance]) -> bool:
    """Whether ``new`` holds the very instances of ``old``, in order (not merely equal ones:
    ``-0.0 == 0.0``, but their bytes differ)."""
    return len(old) == len(new) and all(map(operator.is_, old, new))


def _head(content: MissionContent) -> bytes:
    """A body's bytes before its first task: the library and the number of tasks."""
    return string_bytes(content.library) + _COUNT.pack(len(content.tasks))


def _task_head(agent: str, task: Sequence[SkillInstance]) -> bytes:
    """A task's bytes before its skills: its agent and number of skills."""
    return string_bytes(agent) + _COUNT.pack(len(task))


def _tail(content: MissionContent) -> bytes:
    """A body's bytes after its tasks: the barriers and markers."""
    agent_of = _agents_of_members(content).__getitem__
    barriers = _array(barrier_to_msg(b, agent_of) for b in content.barriers.values())
    return barriers + _array(marker_to_msg(m) for m in content.markers.values())


def _is_prepared(content: MissionContent, prepared: PackedBody) -> bool:
    """Whether the prepared body is byte for byte the body of ``content``."""
    tasks = prepared.tasks
    if not tasks or list(tasks) != list(content.tasks):
        return False
    if not all(_same_instances(tasks[a].skills, t) for a, t in content.tasks.items()):
        return False
    head, tail, data = _head(content), _tail(content), prepared.data
    size = len(head) + len(tail)
    size += sum(len(_task_head(a, t)) + tasks[a].span(0, len(t))[1] - tasks[a].start
                for a, t in content.tasks.items())  # fmt: skip
    return len(data) == size and data.startswith(head) and data.endswith(tail)


def _agents_of_members(content: MissionContent) -> dict[str, str]:
    members = {skill_id for barrier in content.barriers.values() for skill_id in barrier.skill_ids}
    if not members:
        return {}
    return {s.id: agent for agent, task in content.tasks.items() for s in task if s.id in members}
