"""Reopening a journal after a crash: which files to read and where writing goes on.

Resume reads only the journal's last file, and the one before it when the last
one does not start a mission on its own (no intact snapshot, or events missing
right after its first snapshot because it was journaled late). A last file
without damage is continued after its last intact record (a torn tail is cut
off and kept beside it as ``<name>.dropped-<offset>``). A last file with damage
stays untouched, for inspection, and writing goes on in the next part file; so
does a file of an older journal, whose head holds no revision mark.

A change that replaces the mission is written as one chunk with its snapshot, but a
journal written before that (or in the bare layout, where a crash can tear the pair
between its two records) may end with the replacement's event alone: a change never
acknowledged. Resume cuts it off (kept beside the file like a torn tail) before anything
is appended, so that no later change can follow it in the file and be lost behind it.
"""

from __future__ import annotations

import logging
import os
from dataclasses import dataclass, replace
from pathlib import Path

import rosmc.msg as wire

from rosmc_server.interface import EVENTS_TOPIC, MISSION_TOPIC
from rosmc_server.recording._mcap import scan as _scan
from rosmc_server.recording._mcap.files import journal_parts, open_locked, part_path, save_tail
from rosmc_server.recording._mcap.write import DataSection, PartFile
from rosmc_server.recording.channels import JOURNAL_TOPICS, PROFILE
from rosmc_server.recording.errors import JournalError
from rosmc_server.recording.reader import JournalResult, decode_scan, join_results

_log = logging.getLogger(__name__)

_KIND_AT = 16  # a MissionEvent's kind: after its uint64 revision and its 8-byte stamp
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
        cut_replacement: The revision of an unfinished replacement cut off the end (None:
            there was none).
    """

    base: Path
    part: PartFile
    recovered: JournalResult
    damaged: bool
    cut_replacement: int | None = None


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
    unfinished = None if scan.damage else unfinished_replacement(scan)
    if unfinished is not None:
        scan = _cut(scan, unfinished[1])
    results = [decode_scan(scan)]
    snapshots = sum(r.topic == MISSION_TOPIC for r in results[0].records)
    earlier = parts[:-1]
    while earlier and _needs_earlier(results):
        results.insert(0, decode_scan(_scan.scan(earlier.pop()[1])))
    recovered = join_results(base, results)
    if results[-1].damage:  # left as it is: its damage stays there to be looked at
        os.close(fd)
        new = part_path(base, number + 1)
        part = PartFile.create(new, number + 1, chunked, durable)
        return Reopened(base, part, recovered, True)
    if unfinished is not None or (not scan.complete and scan.dropped_bytes):
        save_tail(last, scan.data_end)
    os.ftruncate(fd, scan.data_end)
    if durable:  # the cut is down before anything follows it
        os.fdatasync(fd)
    offset = os.lseek(fd, 0, os.SEEK_END)
    part = PartFile(
        last, number, fd, section_from_scan(scan), offset, chunked, snapshots, scan.mark_slots
    )
    tail = part.section.restore_indexes(offset, scan.missing_indexes)
    tail += part.section.declare(JOURNAL_TOPICS)
    if tail:
        part.write(tail, sync=True, durable=durable)
    if part.slots is None:  # a file of an older journal: its head has no room for the mark
        part.close()
        part = PartFile.create(part_path(base, number + 1), number + 1, chunked, durable)
    cut = None if unfinished is None else unfinished[0]
    return Reopened(base, part, recovered, False, cut)


def unfinished_replacement(scan: _scan.ScanResult) -> tuple[int, int] | None:
    """The revision and file offset of a MISSION_REPLACED event the file ends with before
    its snapshot (a change never acknowledged), or None.

    Read from the records' bytes: a ``rosmc/MissionEvent`` starts with its ``uint64
    revision``, an 8-byte stamp and its ``uint8 kind``; a ``rosmc/Mission`` with its
    ``uint64 revision``.
    """
    ids = {channel.topic: channel.id for channel in scan.channels.values()}
    events, snapshots = ids.get(EVENTS_TOPIC), ids.get(MISSION_TOPIC)
    last = max((i for i, m in enumerate(scan.messages) if m.channel_id == events), default=None)
    if last is None:
        return None
    data = scan.messages[last].data
    if len(data) <= _KIND_AT or data[_KIND_AT] != wire.MissionEvent.MISSION_REPLACED:
        return None
    revision = int.from_bytes(data[:8], "little")
    for msg in scan.messages[last + 1 :]:
        if msg.channel_id == snapshots and int.from_bytes(msg.data[:8], "little") == revision:
            return None
    return revision, scan.spans[last][0]


def _cut(scan: _scan.ScanResult, offset: int) -> _scan.ScanResult:
    """The scan without the records at ``offset`` and after (their bytes are cut off)."""
    kept = [i for i, (start, _) in enumerate(scan.spans) if start < offset]
    return replace(
        scan,
        messages=[scan.messages[i] for i in kept],
        spans=[scan.spans[i] for i in kept],
        chunk_indexes=[c for c in scan.chunk_indexes if c.chunk_start_offset < offset],
        missing_indexes={},
        top_level_messages=sum(1 for i in kept if not scan.chunk_indexes),
        data_end=offset,
        dropped_bytes=scan.size - offset,
    )


def _needs_earlier(results: list[JournalResult]) -> bool:
    """Whether the files read so far need the one before them to start the mission.

    They do without an intact snapshot, or when the first event newer than their first
    snapshot does not follow it (that snapshot was journaled late, after events that
    went into the earlier file).
    """
    first: int | None = None
    for record in (r for result in results for r in result.records):
        if record.topic not in (MISSION_TOPIC, EVENTS_TOPIC):
            continue
        revision = record.revision  # read from the bytes: a snapshot is not decoded
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
