"""Mission snapshots read from ROS 1 wire bytes straight into core objects.

Part of :mod:`rosmc_server.conversions`; the reverse of :mod:`.packing`. A client that
decodes a 10,000-skill ``rosmc/Mission`` into genpy messages and then converts those
(:func:`~.mission.mission_from_msg`) spends about 100 ms in Python; reading the bytes
straight into :class:`~rosmc_server.core.SkillInstance` objects (the records:
:mod:`.record_unpacking`) takes about a seventh of that. :class:`UnpackedGetMission` is a
service class for ``rospy.ServiceProxy`` whose answers arrive that way (what
:class:`~rosmc_server.ros.client.MissionClient` fetches).

The reader is used only while ``rosmc/Mission`` is the definition it was written for
(its md5sum); otherwise answers go through genpy as before. Tests check it against genpy
and ``mission_from_msg`` for random missions, and that malformed bytes fail as genpy's do.
"""

from __future__ import annotations

import contextlib
import gc
import struct
from collections.abc import Iterator, Mapping
from typing import Any

import genpy
import rosmc.msg as wire
import rosmc.srv as srv

from ..core import (
    Barrier,
    InvalidRequest,
    MarkerType,
    MissionContent,
    Pose,
    SkillInstance,
    TaskMarker,
)
from .mission import mission_from_msg
from .record_unpacking import read_records
from .task_memory import TaskMemory

# The rosmc/Mission definition the reader follows (with its nested types).
UNPACKED_MISSION_MD5 = "afb150ec3f57bc7466152152c338c587"

_COUNT = struct.Struct("<I").unpack_from
_HEADER = struct.Struct("<Q2I")  # revision, stamp
_POSE = struct.Struct("<6d").unpack_from
_MARKER_TYPE = struct.Struct("<B").unpack_from


class UnpackedGetMissionResponse(srv.GetMissionResponse):  # type: ignore[misc]
    """A ``rosmc/GetMission`` answer read into ``content``, ``revision``, ``journal_alert``
    and ``epoch``.

    ``mission`` stays empty: the answer never becomes genpy messages (but when the
    definition changed, see the module's docstring).
    """

    mission: Any
    content: MissionContent
    revision: int
    memory: TaskMemory | None = None  # see remembering_get_mission

    def deserialize(self, data: bytes) -> UnpackedGetMissionResponse:
        """Read the answer's wire bytes (rospy calls this); genpy.DeserializationError if
        they are malformed, InvalidRequest if they hold what no mission can."""
        if wire.Mission._md5sum != UNPACKED_MISSION_MD5:
            super().deserialize(data)
            self.content, self.revision = mission_from_msg(self.mission)
            self.mission = wire.Mission()  # as documented: not kept twice
            return self
        with _reading():
            self.content, self.revision, end = _read_mission(data, 0, self.memory)
            self.journal_alert, end = _text(data, end)
            self.epoch, end = _text(data, end)
        if end != len(data):
            raise genpy.DeserializationError(f"{len(data) - end} bytes after the answer")
        return self


class UnpackedGetMission:
    """The ``rosmc/GetMission`` service, answering with :class:`UnpackedGetMissionResponse`."""

    _type = srv.GetMission._type
    _md5sum = srv.GetMission._md5sum
    _request_class = srv.GetMissionRequest
    _response_class = UnpackedGetMissionResponse


def remembering_get_mission(memory: TaskMemory) -> type:
    """:class:`UnpackedGetMission` whose answers reuse the skills of unchanged records read
    before into ``memory`` (one memory per client: see :mod:`.task_memory`)."""
    response = type(
        "RememberingGetMissionResponse", (UnpackedGetMissionResponse,), {"memory": memory}
    )
    return type("RememberingGetMission", (UnpackedGetMission,), {"_response_class": response})


def mission_from_bytes(data: bytes, start: int = 0) -> tuple[MissionContent, int, int]:
    """The content and revision of the ``rosmc/Mission`` at ``data[start:]``, and where it ends.

    Raises:
        genpy.DeserializationError: The bytes end early or are not a mission.
        InvalidRequest: The mission holds an unknown status, type or marker number, a
            parameter without a name or with malformed JSON (as ``mission_from_msg``).
    """
    with _reading():
        return _read_mission(data, start)


@contextlib.contextmanager
def _reading() -> Iterator[None]:
    """Read without the cyclic collector (thousands of new containers, none in a cycle);
    bytes that end early or hold nonsense counts raise genpy.DeserializationError."""
    was_enabled = gc.isenabled()
    gc.disable()
    try:
        yield
    except (struct.error, IndexError, OverflowError) as error:
        raise genpy.DeserializationError(f"a malformed rosmc/Mission: {error}") from error
    finally:
        if was_enabled:
            gc.enable()


def _read_mission(
    data: bytes, pos: int, memory: TaskMemory | None = None
) -> tuple[MissionContent, int, int]:
    revision = _HEADER.unpack_from(data, pos)[0]
    library, pos = _text(data, pos + _HEADER.size)
    (count,) = _COUNT(data, pos)
    pos += 4
    tasks: dict[str, list[SkillInstance]] = {}
    fresh: dict[str, Any] = {}
    for _ in range(count):
        agent, pos = _text(data, pos)
        if memory is None:
            tasks[agent], pos = _read_skills(data, pos)
        else:
            tasks[agent], pos = memory.read_task(agent, data, pos, read_records, fresh)
    barriers: dict[str, Barrier] = {}
    (count,) = _COUNT(data, pos)
    pos += 4
    for _ in range(count):
        barrier_id, pos = _text(data, pos)
        members, pos = _texts(data, pos)
        _, pos = _texts(data, pos)  # each member's agent: the core knows it from the tasks
        barriers[barrier_id] = Barrier(barrier_id, tuple(members))
    markers: dict[str, TaskMarker] = {}
    (count,) = _COUNT(data, pos)
    pos += 4
    for _ in range(count):
        marker, pos = _read_marker(data, pos)
        markers[marker.name] = marker
    if pos > len(data):
        raise genpy.DeserializationError("the bytes end inside the mission")
    if memory is not None:
        memory.remember(fresh)
    return MissionContent(library, tasks, barriers, markers), revision, pos


def _read_skills(data: bytes, pos: int) -> tuple[list[SkillInstance], int]:
    """The ``rosmc/Skill[]`` at ``pos`` as core skills, and where it ends."""
    skills: list[SkillInstance] = []
    end = read_records(data, pos + 4, _COUNT(data, pos)[0], skills, None)
    return skills, end


def _read_marker(data: bytes, pos: int) -> tuple[TaskMarker, int]:
    name, pos = _text(data, pos)
    (type_number,) = _MARKER_TYPE(data, pos)
    pose = Pose(*_POSE(data, pos + 1))
    pos += 49
    (count,) = _COUNT(data, pos)
    pos += 4
    vertices = []
    for _ in range(count):
        vertices.append(Pose(*_POSE(data, pos)))
        pos += 48
    marker_type = _enum(_MARKER_TYPES, type_number, "marker type")
    return TaskMarker(name, marker_type, pose, tuple(vertices)), pos


def _text(data: bytes, pos: int) -> tuple[str, int]:
    """The ROS string at ``pos`` and where it ends (undecodable bytes replaced, as genpy does)."""
    size = _COUNT(data, pos)[0]
    pos += 4
    return data[pos : pos + size].decode("utf-8", "rosmsg"), pos + size


def _texts(data: bytes, pos: int) -> tuple[list[str], int]:
    """The ROS ``string[]`` at ``pos`` and where it ends."""
    (count,) = _COUNT(data, pos)
    pos += 4
    texts = []
    for _ in range(count):
        text, pos = _text(data, pos)
        texts.append(text)
    return texts, pos


def _enum(members: Mapping[int, Any], number: int, what: str) -> Any:
    """The member numbered ``number``; InvalidRequest as ``enum_from_number`` says it."""
    member = members.get(number)
    if member is None:
        raise InvalidRequest(f"unknown {what} number {number}")
    return member


_MARKER_TYPES: Mapping[int, MarkerType] = {int(m): m for m in MarkerType}
