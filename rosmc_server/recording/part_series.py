"""The files of one journal: the part written now, when the next begins, the mark in each head.

A journal that grows past ``part_bytes`` (or ``part_changes`` events) goes on in part files
beside the first (:mod:`._mcap.files`). This module decides when, starts the next part,
and keeps the revision mark in the head of the part written and of the journal's first
file (:mod:`._mcap.head_mark`), so that any part can tell a resume how far revisions went.
What goes into the records is :class:`~.writer.JournalWriter`'s; it holds its lock around
every call here.
"""

import logging
from collections.abc import Mapping
from pathlib import Path

from rosmc_server.interface import EVENTS_TOPIC
from rosmc_server.recording._mcap import head_mark
from rosmc_server.recording._mcap.files import part_path
from rosmc_server.recording._mcap.write import PartFile
from rosmc_server.recording.errors import JournalError
from rosmc_server.recording.journal_options import JournalOptions

_log = logging.getLogger(__name__)


class PartSeries:
    """The part file being written and the parts before it (not thread-safe: the writer
    serialises calls).

    Attributes:
        part: The file appends go to now.
        channels: Its channel ids by topic.
        events_in_part: Mission events written to it.
    """

    def __init__(self, base: Path, part: PartFile, options: JournalOptions) -> None:
        self.base = base
        self.part = part
        self.channels = part.section.channel_ids()
        self.events_in_part = part.section.counts.get(self.channels.get(EVENTS_TOPIC, -1), 0)
        self._options = options
        self._rotation_failed = False
        self._mark: dict[str, str | int] | None = None  # the revision mark, for new parts
        self._mark_writes = 0
        self._first_head: head_mark.FirstFileHead | None = None  # once parts follow it

    def full(self) -> bool:
        """Whether the current file holds ``part_bytes`` bytes or ``part_changes`` events."""
        return (
            self.part.offset >= self._options.part_bytes
            or self.events_in_part >= self._options.part_changes
        )

    def rotation_due(self, snapshot: bool, late: bool) -> bool:
        """Whether the next append starts a new part: a full part starts one with a snapshot,
        so the part can start the mission on its own (any record does at twice the size).
        A periodic snapshot journaled late (older than events already written) never does:
        a resume that read the new part alone would miss those events. Nor is a part left
        before it holds a snapshot: it could start nothing."""
        if self._rotation_failed or late or not self.full() or not self.part.snapshots:
            return False
        return snapshot or self.part.offset >= 2 * self._options.part_bytes

    def rotate(self) -> None:
        """Go on in the next part file; on failure keep writing this one."""
        old = self.part
        number = old.number + 1
        try:
            new = PartFile.create(
                part_path(self.base, number), number, old.chunked, self._options.fsync
            )
        except JournalError as err:
            _log.warning(
                "journal %s: cannot start its next part (%s); going on in %s",
                self.base,
                err,
                old.path.name,
            )
            self._rotation_failed = True
            return
        self.part = new
        self.channels = new.section.channel_ids()
        self.events_in_part = 0
        if self._mark is not None:
            self._mark_writes += 1
            try:
                new.write_mark(self._mark, self._mark_writes)
            except JournalError as err:  # the side file and the older parts still hold it
                _log.warning("journal %s: %s", self.base, err)
        try:
            old.close()
        except JournalError as err:  # readers recover an unclosed part all the same
            _log.warning("journal %s: %s", self.base, err)
        _log.info("journal %s: continuing in %s", self.base, new.path.name)

    def write_mark(self, fields: Mapping[str, str | int], sync: bool) -> None:
        """Keep the revision mark in the head of the part written and of the first file
        (synced when ``sync``, once parts follow it), and in every part started after this.

        Raises:
            JournalError: A head cannot be written.
        """
        self._mark = dict(fields)
        self._mark_writes += 1
        self.part.write_mark(self._mark, self._mark_writes)
        if self.part.number == 1:
            return
        if self._first_head is None:
            self._first_head = head_mark.FirstFileHead(self.base)
        try:
            self._first_head.write(self._mark, self._mark_writes, sync and self._options.fsync)
        except OSError as err:
            raise JournalError(f"cannot write journal {self.base}: {err.strerror}") from err

    def close_first_head(self) -> None:
        """Let go of the first file's head (the journal is closing)."""
        if self._first_head is not None:
            self._first_head.close()
            self._first_head = None
