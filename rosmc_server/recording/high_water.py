"""The revision high-water mark of a journal, kept apart from its body.

A journal can lose its end (a disk zeroes or cuts it from the last snapshot on) and still
read as a journal a crash merely cut short: from the body alone a resume cannot tell, and
would hand out revision numbers operators already saw. So beside ``<journal>`` the server
keeps ``<journal>.revisions``, one fixed-size line of JSON::

    {"epoch": "3f9a01c2", "revision": 8000, "high_water": 8500}

* ``revision``, the last acknowledged revision, is rewritten in place after every change
  (no fsync of its own: a process crash keeps it, a power loss may leave an older one);
* ``high_water`` is a lease: revisions up to it may have been handed out. It is renewed,
  and the file fsynced, before a revision could pass it, every :data:`LEASE` changes;
* ``epoch`` names the mission's history; a resume that lost history starts a new one.

A resume that finds the journal behind ``revision`` (or damaged) goes on above
``high_water``, so no revision number repeats within a mission's life, whatever was lost.

The same mark is kept a second time inside the journal, at the head of the file being
written (:mod:`._mcap.head_mark`), where a journal copied without its side file, or cut
short or zeroed from some point on, still holds it. :func:`recover_mark` reads both and
takes the higher; when one copy had to stand in for the other, it says so as an alert.
Only when both are lost (the side file gone *and* the head of every part damaged) is the
mark unknown: the resume then goes on a whole :data:`LEASE` above the journal's last
revision, in a new epoch, and says so.
"""

from __future__ import annotations

import json
import logging
import os
import secrets
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from pathlib import Path

from rosmc_server.core.documents.durable import fsync_directory

_log = logging.getLogger(__name__)

LEASE = 500
"""Revisions handed out between two fsyncs of the mark."""
_SIZE = 128  # bytes of the line, padded: rewritten in place, it never grows


@dataclass(frozen=True)
class Mark:
    """What a mark file says: the history's epoch, its last revision and the lease."""

    epoch: str
    revision: int
    high_water: int


def mark_path(journal: Path) -> Path:
    """The mark file of a journal (beside its first file)."""
    return journal.with_name(journal.name + ".revisions")


def read_mark(journal: Path) -> Mark | None:
    """The mark of ``journal``; None if it has none (an older journal) or it is unreadable."""
    try:
        data = json.loads(mark_path(journal).read_bytes().decode("ascii"))
        return Mark(str(data["epoch"]), int(data["revision"]), int(data["high_water"]))
    except FileNotFoundError:
        return None
    except (OSError, ValueError, KeyError, TypeError) as err:
        _log.error("journal %s: its revision mark is unreadable (%s)", journal, err)
        return None


def new_epoch() -> str:
    """A fresh epoch name: 8 hex digits, random (no two histories share one in practice)."""
    return secrets.token_hex(4)


MarkCopy = Callable[[Mapping[str, str | int], bool], None]
"""Where a second copy of the mark goes, and whether to sync it (the journal's heads:
``JournalWriter.write_mark``)."""


class RevisionMark:
    """The open mark file of a journal being written, and its copy in the journal's head.
    Not thread-safe (the server's lock)."""

    def __init__(
        self, journal: Path, mark: Mark, durable: bool, copy: MarkCopy | None = None
    ) -> None:
        """Create or replace the mark file with ``mark`` (fsynced, with its directory), and
        write it to ``copy`` (never synced on its own: the journal's next record is).

        The file is written whole beside its place and renamed onto it, so that a crash
        never leaves an empty or half-written mark file; later updates rewrite its one
        short line in place (a write of one sector: whole or not at all).
        """
        self.path = mark_path(journal)
        self._durable = durable
        self._copy = copy
        self.mark = mark
        staged = self.path.with_name(self.path.name + ".new")
        self._fd = os.open(staged, os.O_RDWR | os.O_CREAT | os.O_TRUNC, 0o644)
        try:
            self._write(sync=True, to_copy=False)
            os.replace(staged, self.path)
        except OSError:
            self.close()
            raise
        if durable:
            fsync_directory(self.path.parent)
        if copy is not None:  # second: a crash between the two leaves the side file newer
            copy(mark_fields(mark), True)

    @property
    def epoch(self) -> str:
        """The epoch of the mission's history."""
        return self.mark.epoch

    def record(self, revision: int) -> None:
        """Note ``revision`` as acknowledged; renew the lease (fsynced) before it runs out.

        Raises:
            OSError: The mark cannot be written.
        """
        high_water = self.mark.high_water
        renew = revision + LEASE // 2 > high_water
        if renew:
            high_water = revision + LEASE
        self.mark = Mark(self.mark.epoch, revision, high_water)
        self._write(sync=renew)

    def close(self) -> None:
        """Close the file."""
        if self._fd >= 0:
            os.close(self._fd)
            self._fd = -1

    def _write(self, sync: bool, to_copy: bool = True) -> None:
        mark = self.mark
        line = json.dumps(mark_fields(mark))
        data = line.encode("ascii").ljust(_SIZE - 1) + b"\n"
        os.pwrite(self._fd, data, 0)
        if sync and self._durable:
            os.fdatasync(self._fd)
        if to_copy and self._copy is not None:  # second: the side file is never the older
            self._copy(mark_fields(mark), sync)


def mark_fields(mark: Mark) -> dict[str, str | int]:
    """The mark as the fields of a JSON object."""
    return {"epoch": mark.epoch, "revision": mark.revision, "high_water": mark.high_water}


def first_mark(revision: int) -> Mark:
    """The mark of a new journal whose mission starts at ``revision``."""
    return Mark(new_epoch(), revision, revision + LEASE)


def resumed_mark(previous: Mark | None, revision: int, lost_history: bool) -> Mark:
    """The mark a resumed journal goes on with, its mission at ``revision``.

    After lost history the epoch is new and ``revision`` must already be above the old
    lease (see :func:`next_after_loss`).
    """
    if previous is None:
        return first_mark(revision)
    epoch = new_epoch() if lost_history else previous.epoch
    return Mark(epoch, revision, max(previous.high_water, revision + LEASE))


def next_after_loss(previous: Mark | None, next_revision: int) -> int:
    """The revision the next change gets after a resume that lost history: above every
    revision the journal holds and every one the old lease may have handed out."""
    if previous is None:
        return next_revision
    return max(next_revision, previous.high_water + 1)
