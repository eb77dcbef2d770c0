"""File-system helpers of the journal: its chain of part files, exclusive opening, tails.

A journal is one file, ``mission_X.mcap``, until it grows past
:attr:`JournalOptions.part_bytes`; then the writer continues in
``mission_X.part002.mcap``, ``mission_X.part003.mcap``, ... (and after a resume
that found damage, in the next part too). Each part is a complete MCAP file of
its own. The first file's name stands for the whole chain: every reader and
resume follow it.
"""

import errno
import fcntl
import logging
import os
import re
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
    while path.exists() or len(journal_parts(path)[1]) > 1:  # parts of a journal moved away
        number += 1
        path = directory / f"{stem}_{number}.mcap"
    return path


_PART = re.compile(r"^(?P<stem>.+)\.part(?P<number>\d{3,})(?P<suffix>\.[^.]*)?$")


def part_path(base: Path, number: int) -> Path:
    """The file of part ``number`` (1 is ``base`` itself) of the journal ``base``."""
    if number == 1:
        return base
    return base.with_name(f"{base.stem}.part{number:03d}{base.suffix}")


def journal_parts(path: str | Path) -> tuple[Path, list[tuple[int, Path]]]:
    """The journal a file belongs to and its parts that exist, as (number, file), in order.

    ``path`` may name the first file or any part; a part whose first file is gone is
    read on its own.
    """
    path = Path(path)
    match = _PART.match(path.name)
    base = path
    if match is not None:
        first = path.with_name(match["stem"] + (match["suffix"] or ""))
        if first.exists():
            base = first
    parts = [(1, base)]
    for candidate in base.parent.glob(f"{_glob_escape(base.stem)}.part*{base.suffix}"):
        found = _PART.match(candidate.name)
        if found is not None and part_path(base, int(found["number"])) == candidate:
            parts.append((int(found["number"]), candidate))
    return base, sorted(parts)


def _glob_escape(text: str) -> str:
    return re.sub(r"([*?\[])", r"[\1]", text)


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
