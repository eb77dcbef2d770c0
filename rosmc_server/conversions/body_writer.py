"""Where a packed snapshot's skill bytes are: one body, and each task's offsets into it.

Part of :mod:`rosmc_server.conversions` (used by :class:`~.packing.SnapshotPacker`). A
snapshot of 10,000 skills is megabytes; keeping each skill's bytes as a bytes object of its
own beside the body joined from them held them twice. :class:`PackedTask` says where a
task's skills are in a body instead, and :class:`BodyWriter` writes the next body, copying
each run of skills reused from a body before in one piece.
"""

from __future__ import annotations

import io
from array import array
from dataclasses import dataclass

from ..core import SkillInstance


@dataclass(frozen=True)
class PackedTask:
    """An agent's task as packed: its skills, and where their bytes are in ``data``.

    ``data`` is a whole snapshot body (or a prepared one): the skills' bytes are kept once,
    in it, as offsets, not as a bytes object per skill beside it.
    """

    skills: list[SkillInstance]
    data: bytes
    start: int  # where the first skill's bytes start in data
    ends: array[int]  # where each skill's bytes end, counted from start

    def span(self, first: int, last: int) -> tuple[int, int]:
        """Where the bytes of skills ``first`` to ``last`` (excluded) are in ``data``."""
        begin = self.ends[first - 1] if first else 0
        return self.start + begin, self.start + (self.ends[last - 1] if last else 0)


@dataclass(frozen=True)
class PackedBody:
    """A snapshot body and its tasks, as :meth:`SnapshotPacker.body` built it."""

    data: bytes
    tasks: dict[str, PackedTask]
    taken: tuple[str, ...] = ()  # tasks taken whole from a prepared body (and copied)


class BodyWriter:
    """Writes a body, copying runs of reused skill bytes in one piece each."""

    def __init__(self) -> None:
        self.out = io.BytesIO()
        self._run: tuple[bytes, int, int] | None = None  # reused bytes not written yet

    def write(self, data: bytes) -> None:
        """Write new bytes."""
        self.flush()
        self.out.write(data)

    def reuse(self, data: bytes, begin: int, end: int) -> None:
        """Write ``data[begin:end]`` (joined to the run before when it follows it there)."""
        run = self._run
        if run is not None and run[0] is data and run[2] == begin:
            self._run = (data, run[1], end)
            return
        self.flush()
        self._run = (data, begin, end)

    def flush(self) -> None:
        """Write the pending run of reused bytes."""
        if self._run is not None:
            data, begin, end = self._run
            self.out.write(memoryview(data)[begin:end])
            self._run = None

    def tell(self) -> int:
        """Bytes written so far (the pending run included)."""
        run = self._run
        return self.out.tell() + (run[2] - run[1] if run is not None else 0)

    def value(self) -> bytes:
        """The bytes written (the buffer itself, not a copy of it)."""
        self.flush()
        return self.out.getvalue()
