"""A client's memory of the tasks it read last, so that reading the next snapshot costs the change.

Part of :mod:`rosmc_server.conversions`, beside :mod:`.unpacking`. Reading a snapshot of
20,000 skills into core objects takes tens of milliseconds, though between two reads
mostly nothing, or a few skills, changed. A :class:`TaskMemory` keeps, per agent, the
bytes of the ``rosmc/Skill[]`` last read, where each skill's record starts in them, and
the skills read from them. In the next snapshot, records whose bytes are unchanged are
the same skills again (skills are immutable, so they are shared, not copied): a task
equal to the last is one comparison of bytes, and in a changed task the unchanged
stretches are found with a few comparisons each (doubling, then halving, the stretch
compared), so only the changed records are read.

Equal bytes read as equal skills, so what comes out is what reading every record gives
(a test compares both over random changes).
"""

from __future__ import annotations

import struct
import threading
from collections.abc import Callable
from dataclasses import dataclass

from ..core import SkillInstance

_COUNT = struct.Struct("<I").unpack_from
_GIVE_UP = 16  # records read one after another before the rest is read at once

# unpacking.read_records: read ``count`` records from ``pos`` onto the lists; where they end.
ReadRecords = Callable[[bytes, int, int, list[SkillInstance], "list[int] | None"], int]


@dataclass(frozen=True)
class _Task:
    """A task as last read: its bytes (count, then records), record starts, skills."""

    data: bytes
    starts: list[int]  # each record's offset in data, then len(data)
    skills: list[SkillInstance]


class TaskMemory:
    """The tasks read from the last snapshot, by agent. Safe to share between threads."""

    def __init__(self) -> None:
        self._tasks: dict[str, _Task] = {}
        self._lock = threading.Lock()

    def read_task(
        self,
        agent: str,
        data: bytes,
        pos: int,
        read: ReadRecords,
        fresh: dict[str, _Task],
    ) -> tuple[list[SkillInstance], int]:
        """The skills of ``agent``'s task at ``pos`` and where it ends; what was read goes
        into ``fresh`` (see :meth:`remember`)."""
        with self._lock:
            last = self._tasks.get(agent)
        if last is not None and data[pos : pos + len(last.data)] == last.data:
            fresh[agent] = last  # unchanged
            return list(last.skills), pos + len(last.data)
        skills: list[SkillInstance] = []
        starts: list[int] = []
        count = _COUNT(data, pos)[0]
        if last is None:
            end = read(data, pos + 4, count, skills, starts)
        else:
            end = _read_changed(data, pos + 4, count, last, read, skills, starts)
        starts.append(end)
        fresh[agent] = _Task(data[pos:end], [at - pos for at in starts], skills)
        return list(skills), end

    def remember(self, fresh: dict[str, _Task]) -> None:
        """Keep the tasks of a snapshot read whole (and forget the agents it lacks)."""
        with self._lock:
            self._tasks = fresh


def _read_changed(
    data: bytes,
    pos: int,
    count: int,
    last: _Task,
    read: ReadRecords,
    skills: list[SkillInstance],
    starts: list[int],
) -> int:
    """Read ``count`` records from ``pos``, taking each unchanged stretch from ``last``."""
    done = 0
    after = 0  # the record of last that follows the last one taken over
    misses = 0
    while done < count:
        if misses >= _GIVE_UP:  # many changed records in a row: read the rest at once
            return read(data, pos, count - done, skills, starts)
        # Where an unchanged stretch would resume: after the last one taken over (a
        # record changed, one removed or one added), or where the rest ends as in last.
        for first in (after, after + 1, after - 1, len(last.skills) - (count - done)):
            taken = _unchanged(data, pos, last, first, count - done)
            if taken:
                break
        if taken:
            for index in range(first, first + taken):
                starts.append(pos + last.starts[index] - last.starts[first])
            skills += last.skills[first : first + taken]
            pos += last.starts[first + taken] - last.starts[first]
            done += taken
            after = first + taken
            misses = 0
            continue
        misses += 1
        pos = read(data, pos, 1, skills, starts)
        done += 1
        after += 1  # a changed record in place of one of last's (or a new one)
    return pos


def _unchanged(data: bytes, pos: int, last: _Task, first: int, most: int) -> int:
    """How many records of ``last``, from its record ``first``, stand unchanged at ``pos``
    (at most ``most``): the stretch compared doubles while it matches, then halves."""
    total = len(last.skills)
    if not 0 <= first < total:
        return 0
    most = min(most, total - first)
    starts, old = last.starts, last.data
    offset = pos - starts[first]  # from a place in last.data to the same place in data

    def same(count: int) -> bool:  # the ``count`` records after the ``taken`` ones
        begin, end = starts[first + taken], starts[first + taken + count]
        return data[begin + offset : end + offset] == old[begin:end]

    taken, step = 0, 1
    while taken + step <= most and same(step):
        taken += step
        step *= 2
    step //= 2
    while step:
        if taken + step <= most and same(step):
            taken += step
        step //= 2
    return taken
