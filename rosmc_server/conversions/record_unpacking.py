"""The skill records of a snapshot read from ROS 1 wire bytes into core skills.

Part of :mod:`rosmc_server.conversions`, the hot loop of :mod:`.unpacking` (a snapshot
holds tens of thousands of ``rosmc/Skill`` records). Reading runs in two passes: a walk
over the records gathers each field into a column, then the text columns are decoded
and the skills filled a column at a time (:meth:`SkillInstance.assemble_columns`), both
in C, which is about half the time of building each skill in turn.

Most of a record repeats: the records of one task share their agent, and skills of one
kind often carry the same parameters (the library's defaults) and the same numbers
(status ... times; a blueprint's are all alike). Each kind's last record after its
label (parameters, then numbers) is kept as bytes: a record whose rest is those bytes
is the same values, taken with one comparison. The encoding delimits itself, so bytes
equal to a whole earlier field are that field; skills are immutable, so sharing their
values is safe. Tests check the reader against genpy and ``mission_from_msg``.
"""

from __future__ import annotations

import struct
from collections.abc import Iterable, Mapping
from itertools import repeat
from typing import Any

from ..core import InvalidRequest, Resolution, SkillInstance, SkillStatus, Transfer
from ..core.model.model import NO_BINDINGS
from .param_unpacking import read_params

_COUNT = struct.Struct("<I").unpack_from
_SKILL_NUMBERS = struct.Struct("<3BIdI").unpack_from  # status ... max_retries
# The usual form in one read: a skill's tail with an empty status_text (status ...
# max_retries, status_text's length, started, finished). It is at most as long as the
# field run it starts, so valid bytes never end inside it.
_SKILL_TAIL = struct.Struct("<3BIdII2d")
_TIMES = struct.Struct("<2d").unpack_from  # started, finished
_SHARED_MOST = 4096  # parameter blocks (and numbers) kept for sharing per call
_SHARE_TRIES = 64  # records in a row with parameters not read before, then sharing stops

# A record's fields from its skill name on, but the label: skill, params, bindings,
# status, transfer, resolution, attempt, timeout, max_retries, status_text, started,
# finished.
Rest = tuple[Any, ...]


def read_records(
    data: bytes, pos: int, count: int, skills: list[SkillInstance], starts: list[int] | None
) -> int:
    """Read ``count`` ``rosmc/Skill`` records from ``pos`` onto ``skills`` (and where each
    starts onto ``starts``); return where the last ends.

    Strings are read inline, not through a helper (a call per string would cost a fifth
    more). A string read past the end of ``data`` comes out short; the caller checks
    where the mission ends.
    """
    ids: list[bytes] = []
    labels: list[bytes] = []
    rests: list[Rest] = []
    add_id, add_label, add_rest = ids.append, labels.append, rests.append
    mark = (starts if starts is not None else []).append
    agent_field = b""  # the last agent read, with its length
    agents: list[tuple[int, str]] = []  # where the agent changes (a record's index), to what
    kinds: dict[bytes, tuple[bytes, int, Rest]] = {}  # by name bytes: the kind's last rest
    rest_reader = _RestReader()
    for index in range(count):
        mark(pos)
        end = pos + 4 + _COUNT(data, pos)[0]
        add_id(data[pos + 4 : end])
        if agent_field and data.startswith(agent_field, end):
            pos = end + len(agent_field)
        else:
            pos = end + 4 + _COUNT(data, end)[0]
            agent_field = data[end:pos]
            agents.append((index, agent_field[4:].decode("utf-8", "rosmsg")))
        end = pos + 4 + _COUNT(data, pos)[0]
        raw_name = data[pos + 4 : end]
        pos = end + 4 + _COUNT(data, end)[0]
        add_label(data[end + 4 : pos])
        kind = kinds.get(raw_name)
        if kind is not None and data.startswith(kind[0], pos):  # the rest of its kind's last
            pos += kind[1]
            add_rest(kind[2])
            continue
        name = kind[2][0] if kind is not None else raw_name.decode("utf-8", "rosmsg")
        start = pos
        rest, pos = rest_reader.read(data, pos, name)
        kinds[raw_name] = (data[start:pos], pos - start, rest)
        add_rest(rest)
    if count:
        names, *others = zip(*rests, strict=True)  # each rest holds every field
        columns = (_texts(ids), _column(agents, count), names, _texts(labels), *others)
        skills += SkillInstance.assemble_columns(count, columns)
    return pos


def _texts(raws: list[bytes]) -> list[str]:
    """Each text as genpy reads it: UTF-8, undecodable bytes replaced."""
    try:
        return list(map(bytes.decode, raws))  # all valid (the usual case): twice as fast
    except UnicodeDecodeError:
        return [raw.decode("utf-8", "rosmsg") for raw in raws]


def _column(changes: list[tuple[int, str]], count: int) -> Iterable[str]:
    """``count`` values that change where ``changes`` say (from which index, to what)."""
    if len(changes) == 1:
        return repeat(changes[0][1], count)
    ends = [index for index, _ in changes[1:]] + [count]
    column: list[str] = []
    for (start, value), end in zip(changes, ends, strict=True):
        column += repeat(value, end - start)
    return column


class _RestReader:
    """Reads a record's rest (after its label), sharing parameters and numbers read before.

    Parameters are looked up by their bytes (as long as the kind's last ones, so the
    lookup is one slice); after many records in a row with parameters not read before,
    it stops looking (looking would cost more than it saves).
    """

    def __init__(self) -> None:
        self._block_size: dict[str, int] = {}  # by skill name: its last parameters' length
        self._params: dict[bytes, tuple[dict[str, Any], Mapping[str, str]]] = {}  # by bytes
        self._numbers: dict[bytes, tuple[Any, ...]] = {}  # numbers without status text
        self._tries = _SHARE_TRIES  # records left to look in, unless one is found

    def read(self, data: bytes, pos: int, name: str) -> tuple[Rest, int]:
        """The rest of the record of skill ``name`` whose parameters start at ``pos``,
        and where the record ends."""
        params, bindings, pos = self._read_params(data, pos, name)
        field = data[pos : pos + _SKILL_TAIL.size]
        numbers = self._numbers.get(field)
        if numbers is not None:
            pos += _SKILL_TAIL.size
        else:
            numbers, pos = _read_numbers(data, pos)
            if not numbers[6] and len(self._numbers) < _SHARED_MOST:  # the whole field
                self._numbers[field] = numbers
        return (name, params, bindings, *numbers), pos

    def _read_params(
        self, data: bytes, pos: int, name: str
    ) -> tuple[dict[str, Any], Mapping[str, str], int]:
        if not self._tries:  # the parameters were all new lately: reading them is cheaper
            params, bindings, pos = read_params(data, pos)
            return params, bindings or NO_BINDINGS, pos
        size = self._block_size.get(name, 0)
        block = data[pos : pos + size]
        found = self._params.get(block)
        if found is not None:
            self._tries = _SHARE_TRIES
            return found[0], found[1], pos + size
        start = pos
        params, bindings, pos = read_params(data, pos)
        self._tries -= 1
        if pos - start != size:
            self._block_size[name] = pos - start
            block = data[start:pos]
        found = (params, bindings or NO_BINDINGS)
        if len(self._params) < _SHARED_MOST:  # read before with another kind's length
            found = self._params.setdefault(block, found)
        return found[0], found[1], pos


def _read_numbers(data: bytes, pos: int) -> tuple[tuple[Any, ...], int]:
    """A record's fields after its parameters (status ... finished), and where it ends."""
    numbers = _SKILL_TAIL.unpack_from(data, pos)  # ... max_retries, len(status_text), times
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
        pos += _SKILL_TAIL.size
    status = _STATUS.get(numbers[0])
    transfer = _TRANSFER.get(numbers[1])
    resolution = _RESOLUTION.get(numbers[2])
    if status is None or transfer is None or resolution is None:
        raise _unknown_number(numbers[:3])
    return (status, transfer, resolution, *numbers[3:6], status_text, started, finished), pos


def _unknown_number(numbers: tuple[int, ...]) -> InvalidRequest:
    """The error for a skill's status, transfer and resolution numbers, one unknown."""
    for members, number, what in zip(_SKILL_ENUMS, numbers, _SKILL_ENUM_NAMES, strict=True):
        if number not in members:
            return InvalidRequest(f"unknown {what} number {number}")
    raise AssertionError("every number is known")  # pragma: no cover


_STATUS: Mapping[int, SkillStatus] = {int(s): s for s in SkillStatus}
_TRANSFER: Mapping[int, Transfer] = {int(t): t for t in Transfer}
_RESOLUTION: Mapping[int, Resolution] = {int(r): r for r in Resolution}
_SKILL_ENUMS = (_STATUS, _TRANSFER, _RESOLUTION)
_SKILL_ENUM_NAMES = ("status", "transfer", "resolution")
