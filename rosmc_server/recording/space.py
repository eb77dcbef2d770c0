"""The free space of the journal's disk: changes stop before a write could fail half-way.

A change whose journal write failed would be lost after it was applied, so the server
asks :meth:`DiskSpace.require` before it applies one and refuses it while less than the
reserve is free (the disk of the journal is full). Telemetry, which nobody waits for,
stops earlier, at twice the reserve, so what operators and robots change keeps its room.
Free space is asked of the file system (``statvfs``) each time: changes resume by
themselves once space returns.
"""

from __future__ import annotations

import logging
import os
from pathlib import Path

from rosmc_server.core.errors import StorageFull

_log = logging.getLogger(__name__)

RESERVE_BYTES = 1024 * 1024
"""Free bytes a change needs on the journal's disk: an event, a snapshot of a big mission
(zstd-compressed) and the summary a clean close writes all fit in it."""


class DiskSpace:
    """Watches the free space of the file system that holds a directory.

    Attributes:
        directory: The journal's directory.
        reserve: Free bytes below which changes are refused.
    """

    def __init__(self, directory: Path, reserve: int = RESERVE_BYTES) -> None:
        self.directory = directory
        self.reserve = reserve
        self._full = False

    def free(self) -> int:
        """Bytes an unprivileged writer may still use there (as ``df`` shows them)."""
        stats = os.statvfs(self.directory)
        return int(stats.f_bavail * stats.f_frsize)

    @property
    def full(self) -> bool:
        """Whether the last look found less than the reserve free."""
        return self._full

    def require(self, telemetry: bool = False) -> None:
        """Raise StorageFull unless the reserve (twice it for telemetry) is free.

        The first refusal and the return of space are each logged once.
        """
        needed = self.reserve * (2 if telemetry else 1)
        try:
            free = self.free()
        except OSError as err:  # the directory went away: the write will say so itself
            _log.debug("cannot ask the free space of %s: %s", self.directory, err)
            return
        if free >= needed:
            if self._full and not telemetry:
                self._full = False
                _log.warning("the journal's disk has %d bytes free again: changes resume", free)
            return
        if not telemetry:
            if not self._full:
                _log.error(
                    "the journal's disk is full: %d bytes free in %s (a change needs %d); "
                    "changes are refused until space returns, reads go on",
                    free,
                    self.directory,
                    needed,
                )
            self._full = True
        raise StorageFull(free)

    def alert(self) -> str:
        """One line for ``rosmc status`` while changes are refused ("" otherwise)."""
        if not self._full:
            return ""
        try:
            free = self.free()
        except OSError:
            return ""
        if free >= self.reserve:
            return ""
        return f"{StorageFull(free)} in {self.directory}: changes are refused until space returns"
