"""How a journal is written: the options of :class:`~.writer.JournalWriter`."""

from __future__ import annotations

from dataclasses import dataclass

from rosmc_server.recording.space import RESERVE_BYTES


@dataclass(frozen=True)
class JournalOptions:
    """How a journal is written.

    Attributes:
        fsync: fdatasync after every event and snapshot (the default), so an acknowledged
            change also survives a power loss; False keeps it from a process crash only,
            for about 0.1 ms less per change (``bench/bench_journal.py``).
        chunked: One MCAP chunk (with its message index) per append, so the closed file is
            indexed and its snapshots compressed. False writes bare message records: 80 bytes
            less per event, but no compression, and indexed readers (Foxglove's among them)
            must fall back to reading the whole file. A resumed journal keeps its layout.
        snapshot_every: ``snapshot_due`` turns true after this many events.
        compress_from: zstd-compress a chunk whose records reach this many bytes (snapshots);
            0 never compresses.
        part_bytes: Once a file holds this many bytes, ``snapshot_due`` turns true and the
            next snapshot starts the next part file (any append does at twice the size), so
            the writer's memory and the reading a resume or a review does stay bounded
            however long the journal grows.
        part_changes: Once a file holds this many mission events, ``snapshot_due`` turns
            true and the next snapshot starts the next part file: a small mission's events
            would otherwise fill ``part_bytes`` with tens of thousands of changes, all of
            them read again by a resume.
        reserve_bytes: Free bytes on the journal's disk below which :meth:`JournalWriter.
            require_space` refuses changes (twice this stops telemetry), see :mod:`.space`.
    """

    fsync: bool = True
    chunked: bool = True
    snapshot_every: int = 500
    compress_from: int = 16384
    part_bytes: int = 4 * 1024 * 1024
    part_changes: int = 4000
    reserve_bytes: int = RESERVE_BYTES


DEFAULT_OPTIONS = JournalOptions()
"""The options a journal is written with unless told otherwise (frozen: shared safely)."""
