"""File-system helpers of the journal writer: exclusive opening, tails, directory sync."""

import errno
import fcntl
import logging
import os
from collections.abc import Callable
from datetime import datetime
from pathlib import Path

from rosmc_server.recording.errors import JournalError

_log = logging.getLogger(__name__)


def default_journal_path(directory: str | Path, now: Callable[[], datetime] = datetime.now) -> Path:
    """Return ``<directory>/mission_YYYYmmdd_HHMMSS.mcap`` for now, creating the directory.

    A name already taken gets a ``_2``, ``_3``... suffix, so two servers started within
    the same second never share a journal.
    """
    directory = Path(directory)
    directory.mkdir(parents=True, exist_ok=True)
    stem = now().strftime("mission_%Y%m%d_%H%M%S")
    path = directory / f"{stem}.mcap"
    number = 1
    while path.exists():
        number += 1
        path = directory / f"{stem}_{number}.mcap"
    return path


def open_locked(path: Path, flags: int) -> int:
    """Open ``path`` and take an exclusive advisory lock; raise JournalError if either fails."""
    try:
        fd = os.open(path, flags | os.O_CLOEXEC, 0o644)
    except OSError as err:
        reason = "it already exists" if err.errno == errno.EEXIST else err.strerror
        raise JournalError(f"cannot open journal {path}: {reason}") from err
    try:
        fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except OSError as err:
        os.close(fd)
        raise JournalError(f"journal {path} is open in another writer") from err
    return fd


def save_tail(path: Path, start: int) -> Path:
    """Copy the bytes of ``path`` from ``start`` on beside it, before resume cuts them off."""
    with path.open("rb") as file:
        file.seek(start)
        tail = file.read()
    saved = path.with_name(f"{path.name}.dropped-{start}")
    number = 1
    while saved.exists():  # the same offset cut twice: keep both tails
        number += 1
        saved = path.with_name(f"{path.name}.dropped-{start}.{number}")
    saved.write_bytes(tail)
    _log.warning(
        "journal %s: saved the %d bytes cut off at byte %d to %s", path, len(tail), start, saved
    )
    return saved


def fsync_directory(directory: Path) -> None:
    """Make a new directory entry durable (after creating a journal with fsync on)."""
    fd = os.open(directory, os.O_RDONLY | os.O_DIRECTORY)
    try:
        os.fsync(fd)
    finally:
        os.close(fd)
