"""Reopening a journal after a crash: which files to read and where writing goes on.

Resume reads only the journal's last file, and the one before it when the last
one does not start a mission on its own (no intact snapshot, or events missing
right after its first snapshot because it was journaled late). A last file
without damage is continued after its last intact record (a torn tail is cut
off and kept beside it as ``<name>.dropped-<offset>``). A last file with damage
stays untouched, for inspection, and writing goes on in the next part file.
"""

from __future__ import annotations

import logging
import os
from dataclasses import dataclass
from pathlib import Path

from rosmc_server.interface import EVENTS_TOPIC, MISSION_TOPIC
from rosmc_server.recording._mcap import scan as _scan
from rosmc_server.recording._mcap.files import journal_parts, open_locked, part_path, save_tail
from rosmc_server.recording._mcap.write import DataSection, PartFile
from rosmc_server.recording.channels import JOURNAL_TOPICS, PROFILE
from rosmc_server.recording.errors import JournalError
from rosmc_server.recording.reader import JournalResult, decode_scan, join_results

_log = logging.getLogger(__name__)

_EMPTY_PART = 4096
"""A later part smaller than this that is not even an MCAP header was created just before
a crash: it holds nothing anybody was told about and is replaced."""


@dataclass
class Reopened:
    """What :func:`reopen` found and the file writing goes on in.

    Attributes:
        base: The journal (its first file).
        part: The file to append to, locked and positioned at its end.
        recovered: Every intact record of the files read.
        damaged: The last file was damaged, so ``part`` is a new file.
    """

    base: Path
    part: PartFile
    recovered: JournalResult
    damaged: bool


def reopen(path: Path, chunked: bool, durable: bool) -> Reopened:
    """Recover the journal at ``path`` and open the file to continue it in.

    Args:
        chunked: The layout of a journal that holds no message yet.
        durable: Sync a new part's directory entry.

    Raises:
        JournalError: The file is missing, locked by another writer, or not a journal.
    """
    base, parts = journal_parts(path)
    while True:
        number, last = parts[-1]
        fd = open_locked(last, os.O_RDWR)
        try:
            scan = _scan.scan(last)
        except JournalError:
            os.close(fd)
            if number == 1 or last.stat().st_size >= _EMPTY_PART:
                raise
            _log.warning("journal %s: removed %s, which holds no record", base, last.name)
            last.unlink()
            parts.pop()
            continue
        break
    try:
        return _reopen(base, parts, scan, fd, chunked, durable)
    except (OSError, JournalError) as err:
        os.close(fd)
        if isinstance(err, JournalError):
            raise
        raise JournalError(f"cannot resume journal {path}: {err.strerror}") from err


def _reopen(
    base: Path,
    parts: list[tuple[int, Path]],
    scan: _scan.ScanResult,
    fd: int,
    chunked: bool,
    durable: bool,
) -> Reopened:
    number, last = parts[-1]
    if scan.profile != PROFILE:
        raise JournalError(f"{last} is an MCAP file of profile {scan.profile!r}, not a journal")
    if scan.top_level_messages and scan.chunk_indexes:
        raise JournalError(f"journal {last} mixes chunked and bare messages")
    chunked = bool(scan.chunk_indexes) if scan.messages else chunked
    results = [decode_scan(scan)]
    snapshots = sum(r.topic == MISSION_TOPIC for r in results[0].records)
    earlier = parts[:-1]
    while earlier and _needs_earlier(results):
        results.insert(0, decode_scan(_scan.scan(earlier.pop()[1])))
    recovered = join_results(base, results)
    if results[-1].damage:  # found by the scan, or as messages that do not decode
        os.close(fd)  # left as it is: its damage stays there to be looked at
        new = part_path(base, number + 1)
        return Reopened(base, PartFile.create(new, number + 1, chunked, durable), recovered, True)
    if not scan.complete and scan.dropped_bytes:
        save_tail(last, scan.data_end)
    os.ftruncate(fd, scan.data_end)
    offset = os.lseek(fd, 0, os.SEEK_END)
    part = PartFile(last, number, fd, section_from_scan(scan), offset, chunked, snapshots)
    tail = part.section.restore_indexes(offset, scan.missing_indexes)
    tail += part.section.declare(JOURNAL_TOPICS)
    if tail:
        part.write(tail, sync=True, durable=durable)
    return Reopened(base, part, recovered, False)


def _needs_earlier(results: list[JournalResult]) -> bool:
    """Whether the files read so far need the one before them to start the mission.

    They do without an intact snapshot, or when the first event newer than their first
    snapshot does not follow it (that snapshot was journaled late, after events that
    went into the earlier file).
    """
    first: int | None = None
    for record in (r for result in results for r in result.records):
        revision = int(getattr(record.message, "revision", -1))
        if record.topic == MISSION_TOPIC and first is None:
            first = revision
        elif record.topic == EVENTS_TOPIC and first is not None and revision > first:
            return revision > first + 1
    return first is None


def section_from_scan(scan: _scan.ScanResult) -> DataSection:
    """Rebuild the state of the data section a scan found, to go on writing after it."""
    section = DataSection(dict(scan.schemas), dict(scan.channels))
    for index in scan.chunk_indexes:
        section.add_index(index)
    for msg in scan.messages:
        section.count(msg.channel_id, msg.log_time)
    return section
