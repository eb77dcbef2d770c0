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
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from typing import Any

import genpy
import rosmc.msg as wire
import rosmc.srv as srv

from ..core import MissionContent, ParamType, Pose, SkillInstance, Value
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
    parameters, see :mod:`~rosmc_server.core.shared_params`): pass one dict to the calls
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


@dataclass(frozen=True)
class _PackedTask:
    """An agent's task as packed: its skills and the bytes of each, in order."""

    skills: list[SkillInstance]
    parts: list[bytes]


class SnapshotPacker:
    """Builds packed mission snapshots, serializing only the skills changed since the last.

    Skill instances are frozen and replaced by a new instance on every change, so an
    instance still in the mission has the bytes it had last time: a task that holds the
    very instances of last time is reused whole (checked in C, position by position), and
    a changed task reuses the bytes of each skill still there. :meth:`prepare` serializes
    a mission ahead (one about to be loaded, outside the server's lock). Safe to call from
    several threads at once.
    """

    def __init__(self) -> None:
        self._tasks: dict[str, _PackedTask] = {}  # the last snapshot's, by agent
        self._prepared: dict[str, _PackedTask] = {}  # the last prepare's, by agent
        self._names: dict[str, bytes] = {}  # agent, skill and parameter names, encoded
        self._lock = threading.Lock()

    def prepare(self, content: MissionContent) -> None:
        """Serialize the skills of ``content`` now, so that the next snapshot holding them
        is quick.

        Kept until the next call (a snapshot built meanwhile of the old mission does not
        drop them).
        """
        names: dict[str, bytes] = self._names
        shared: dict[int, tuple[Any, Any, bytes]] = {}  # alike parameters written once
        ready = {
            agent: _PackedTask(list(task), [skill_bytes(skill, names, shared) for skill in task])
            for agent, task in content.tasks.items()
        }
        with self._lock:
            self._prepared = ready

    def body(self, content: MissionContent) -> bytes:
        """The wire bytes of a ``rosmc/Mission`` of ``content`` after its revision and stamp."""
        with self._lock:
            previous, prepared = self._tasks, self._prepared
        tasks: dict[str, _PackedTask] = {}
        parts = [string_bytes(content.library), _COUNT.pack(len(content.tasks))]
        for agent, task in content.tasks.items():
            sources = [packed for packed in (previous.get(agent), prepared.get(agent)) if packed]
            packed = next((p for p in sources if _same_instances(p.skills, task)), None)
            if packed is None:
                packed = self._pack_task(task, sources)
            tasks[agent] = packed
            parts += (string_bytes(agent), _COUNT.pack(len(task)))
            parts += packed.parts
        agent_of = _agents_of_members(content).__getitem__
        parts.append(_array(barrier_to_msg(b, agent_of) for b in content.barriers.values()))
        parts.append(_array(marker_to_msg(m) for m in content.markers.values()))
        with self._lock:
            self._tasks = tasks
            taken = [agent for agent, packed in prepared.items() if tasks.get(agent) is packed]
            if taken and self._prepared is prepared:
                # A task this snapshot took over lives on in it; the others wait (a snapshot
                # of the old mission may come first).
                self._prepared = {a: p for a, p in prepared.items() if a not in taken}
        return b"".join(parts)

    def pack(self, content: MissionContent, revision: int, stamp: float) -> PackedMission:
        """A packed snapshot of ``content`` at ``revision``."""
        return PackedMission(revision, time_to_msg(stamp), self.body(content))

    def _pack_task(self, task: Sequence[SkillInstance], sources: list[_PackedTask]) -> _PackedTask:
        """``task`` packed, reusing the bytes of each skill ``sources`` hold (packed before).

        A skill is looked for where it was, or one place off (one inserted, deleted or
        moved before it); only a task that changed in more than a few places (a range
        deleted, many moves) looks skills up by identity.
        """
        nearest = sources[0] if sources else _PackedTask([], [])
        misses = 0
        moved: dict[int, tuple[SkillInstance, bytes]] | None = None
        parts: list[bytes] = []
        for index, skill in enumerate(task):
            if index < len(nearest.skills) and nearest.skills[index] is skill:  # most stay put
                parts.append(nearest.parts[index])
                continue
            part = _near(sources, index, skill)
            if part is None:
                misses += 1
                if moved is None and misses > _FEW_MISSES:
                    moved = {
                        id(s): (s, data)
                        for source in sources
                        for s, data in zip(source.skills, source.parts, strict=True)
                    }
                entry = moved.get(id(skill)) if moved else None
                part = entry[1] if entry is not None and entry[0] is skill else None
            parts.append(part if part is not None else skill_bytes(skill, self._names))
        return _PackedTask(list(task), parts)


_FEW_MISSES = 8  # skills of a task not found near their place before it looks them up by id


def _near(sources: list[_PackedTask], index: int, skill: SkillInstance) -> bytes | None:
    """The bytes of ``skill`` if a source holds it at ``index`` or one place off."""
    for source in sources:
        for at in (index, index + 1, index - 1):
            if 0 <= at < len(source.skills) and source.skills[at] is skill:
                return source.parts[at]
    return None


def _same_instances(old: list[SkillInstance], new: Sequence[SkillInstance]) -> bool:
    """Whether ``new`` holds the very instances of ``old``, in order (not merely equal ones:
    ``-0.0 == 0.0``, but their bytes differ)."""
    return len(old) == len(new) and all(map(operator.is_, old, new))


def _agents_of_members(content: MissionContent) -> dict[str, str]:
    members = {skill_id for barrier in content.barriers.values() for skill_id in barrier.skill_ids}
    if not members:
        return {}
    return {s.id: agent for agent, task in content.tasks.items() for s in task if s.id in members}
