"""Mission snapshots read from ROS 1 wire bytes straight into core objects.

Part of :mod:`rosmc_server.conversions`; the reverse of :mod:`.packing`. A client that
decodes a 10,000-skill ``rosmc/Mission`` into genpy messages and then converts those
(:func:`~.mission.mission_from_msg`) spends about 100 ms in Python; reading the bytes
straight into :class:`~rosmc_server.core.SkillInstance` objects takes about a third of
that. :class:`UnpackedGetMission` is a service class for ``rospy.ServiceProxy`` whose
answers arrive that way (what :class:`~rosmc_server.ros.client.MissionClient` fetches).

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
    Resolution,
    SkillInstance,
    SkillStatus,
    TaskMarker,
    Transfer,
)
from .mission import mission_from_msg
from .param_unpacking import read_params
from .task_memory import TaskMemory

# The rosmc/Mission definition the reader follows (with its nested types).
UNPACKED_MISSION_MD5 = "afb150ec3f57bc7466152152c338c587"

_COUNT = struct.Struct("<I").unpack_from
_HEADER = struct.Struct("<Q2I")  # revision, stamp
_POSE = struct.Struct("<6d").unpack_from
_SKILL_NUMBERS = struct.Struct("<3BIdI").unpack_from  # status ... max_retries
# The usual form in one read: a skill's tail with an empty status_text (status ...
# max_retries, status_text's length, started, finished). It is at most as long as the
# field run it starts, so valid bytes never end inside it.
_SKILL_TAIL = struct.Struct("<3BIdII2d").unpack_from
_TIMES = struct.Struct("<2d").unpack_from  # started, finished
_SHARED_MOST = 4096  # parameter blocks kept for sharing per call (bounds their memory)
_SHARE_TRIES = 64  # records in a row with parameters not read before, then sharing stops
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


def read_records(
    data: bytes, pos: int, count: int, skills: list[SkillInstance], starts: list[int] | None
) -> int:
    """Read ``count`` ``rosmc/Skill`` records from ``pos`` onto ``skills`` (and where each
    starts onto ``starts``); return where the last ends.

    The hot loop of a snapshot: its strings are read inline, not through :func:`_text`
    (a call per string would cost a fifth more). A string read past the end of ``data``
    comes out short; the caller checks where the mission ends.

    Records of one task share their agent, and skills of one kind often carry the same
    parameters (the library's defaults): a record whose agent bytes are the last ones
    read, or whose parameter bytes (as long as its kind's last) equal bytes read before,
    takes those values, shared rather than read again. The encoding delimits itself, so
    bytes equal to a whole earlier field are that field; skills are immutable, so
    sharing is safe. After many records in a row with new parameters the call stops
    looking (looking would cost more than it saves).
    """
    append = skills.append
    mark = starts.append if starts is not None else None
    agent_raw, agent = b"", ""
    block_size: dict[str, int] = {}  # by skill name
    shared: dict[bytes, tuple[dict[str, Any], dict[str, str]]] = {}  # by parameter bytes
    tries = _SHARE_TRIES  # records left to look for shared parameters in, unless one is found
    for _ in range(count):
        if mark is not None:
            mark(pos)
        size = _COUNT(data, pos)[0]
        pos += 4
        skill_id = data[pos : pos + size].decode("utf-8", "rosmsg")
        pos += size
        size = _COUNT(data, pos)[0]
        pos += 4
        if size != len(agent_raw) or not data.startswith(agent_raw, pos):
            agent_raw = data[pos : pos + size]
            agent = agent_raw.decode("utf-8", "rosmsg")
        pos += size
        size = _COUNT(data, pos)[0]
        pos += 4
        name = data[pos : pos + size].decode("utf-8", "rosmsg")
        pos += size
        size = _COUNT(data, pos)[0]
        pos += 4
        label = data[pos : pos + size].decode("utf-8", "rosmsg")
        pos += size
        if not tries:  # the parameters were all new lately: reading them is cheaper
            params, bindings, pos = read_params(data, pos)
        else:
            size = block_size.get(name, 0)  # the length of this kind's last parameters
            block = data[pos : pos + size]
            found = shared.get(block)
            if found is not None:
                params, bindings = found
                pos += size
                tries = _SHARE_TRIES
            else:
                start = pos
                params, bindings, pos = read_params(data, pos)
                tries -= 1
                if pos - start != size:
                    block_size[name] = pos - start
                    block = data[start:pos]
                if len(shared) < _SHARED_MOST:  # read before with another kind's length
                    params, bindings = shared.setdefault(block, (params, bindings))
        numbers = _SKILL_TAIL(data, pos)  # status ... max_retries, len(status_text), times
        if numbers[6]:  # a status text: its bytes stand between the numbers and the times
            numbers = _SKILL_NUMBERS(data, pos)
            size = _COUNT(data, pos + 19)[0]
            status_text = data[pos + 23 : pos + 23 + size].decode("utf-8", "rosmsg")
            pos += 23 + size
            started, finished = _TIMES(data, pos)
            pos += 16
        else:
            status_text = ""
            started, finished = numbers[7], numbers[8]
            pos += 39
        status = _STATUS.get(numbers[0])
        transfer = _TRANSFER.get(numbers[1])
        resolution = _RESOLUTION.get(numbers[2])
        if status is None or transfer is None or resolution is None:
            raise _unknown_number(numbers[:3])
        append(
            _assemble_skill(
                skill_id,
                agent,
                name,
                label,
                params,
                bindings,
                status,
                transfer,
                resolution,
                numbers[3],
                numbers[4],
                numbers[5],
                status_text,
                started,
                finished,
            )
        )
    return pos


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


def _unknown_number(numbers: tuple[int, ...]) -> InvalidRequest:
    """The error for a skill's status, transfer and resolution numbers, one unknown."""
    for members, number, what in zip(_SKILL_ENUMS, numbers, _SKILL_ENUM_NAMES, strict=True):
        if number not in members:
            return InvalidRequest(f"unknown {what} number {number}")
    raise AssertionError("every number is known")  # pragma: no cover


_STATUS: Mapping[int, SkillStatus] = {int(s): s for s in SkillStatus}
_TRANSFER: Mapping[int, Transfer] = {int(t): t for t in Transfer}
_RESOLUTION: Mapping[int, Resolution] = {int(r): r for r in Resolution}
_MARKER_TYPES: Mapping[int, MarkerType] = {int(m): m for m in MarkerType}
_assemble_skill = SkillInstance.assemble
_SKILL_ENUMS = (_STATUS, _TRANSFER, _RESOLUTION)
_SKILL_ENUM_NAMES = ("status", "transfer", "resolution")
