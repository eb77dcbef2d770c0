"""Which revision mark a resume can trust: the side file's, the journal head's, or neither.

The mark (:mod:`.high_water`) is kept twice: in ``<journal>.revisions`` and in the head of
every part file (:mod:`._mcap.head_mark`). A resume takes the higher of the copies that
read, so losing either one loses nothing; when a copy is missing, unreadable or behind the
other, an alert says which one stood in. When a mark existed but no copy of it reads, the
revisions handed out after the journal's last one are unknown: :attr:`RecoveredMark.lost`
tells the resume to go on a whole lease above it.
"""

from __future__ import annotations

import json
import logging
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

from rosmc_server.recording._mcap import head_mark
from rosmc_server.recording.high_water import Mark, mark_path

_log = logging.getLogger(__name__)


@dataclass(frozen=True)
class RecoveredMark:
    """The mark a resume goes on from.

    Attributes:
        mark: The highest copy that reads (None: no copy reads).
        alert: One sentence for ``rosmc status`` when a copy had to stand in for the other,
            or none was left ("" when the side file was there and current).
        lost: A mark existed, but no copy of it reads: revisions after the journal's last
            one may have been handed out.
    """

    mark: Mark | None
    alert: str = ""
    lost: bool = False


def recover_mark(journal: Path, files: Sequence[Path]) -> RecoveredMark:
    """Read the mark of ``journal`` from its side file and the heads of ``files`` (its
    parts), and decide which to trust (see the module docstring)."""
    side, side_state = _side_file(journal)
    heads = [mark for mark in map(_head, files) if mark is not None]
    has_head_slots = any(_has_slots(file) for file in files)
    head = max(heads, key=lambda m: (m.high_water, m.revision), default=None)
    name = mark_path(journal).name
    if head is None:
        if side is not None or (side_state == "missing" and not has_head_slots):
            return RecoveredMark(side)  # an older journal keeps its mark in the side file only
        what = f"its revision mark file {name} is {side_state}"
        if has_head_slots:
            what += " and the journal's own copy does not read"
        return RecoveredMark(None, f"journal: {what}", lost=True)
    if side is None:
        return RecoveredMark(
            head,
            f"journal: its revision mark file {name} was {side_state}; the journal's own copy "
            f"stood in (r{head.revision}, revisions up to r{head.high_water} may have gone out)",
        )
    merged = Mark(
        (side if side.high_water >= head.high_water else head).epoch,
        max(side.revision, head.revision),
        max(side.high_water, head.high_water),
    )
    if side.high_water < head.revision:  # an older copy of the side file, put back
        return RecoveredMark(
            merged,
            f"journal: its revision mark file {name} was behind the journal's own copy "
            f"(r{side.revision} against r{head.revision}); the journal's stood in",
        )
    return RecoveredMark(merged)


def _side_file(journal: Path) -> tuple[Mark | None, str]:
    """The side file's mark and what became of it: "ok", "missing" or "unreadable"."""
    try:
        data = json.loads(mark_path(journal).read_bytes().decode("ascii"))
        return Mark(str(data["epoch"]), int(data["revision"]), int(data["high_water"])), "ok"
    except FileNotFoundError:
        return None, "missing"
    except (OSError, ValueError, KeyError, TypeError) as err:
        _log.error("journal %s: its revision mark file is unreadable (%s)", journal, err)
        return None, "unreadable"


def _read_head(file: Path) -> bytes:
    try:
        with file.open("rb") as stream:
            return stream.read(head_mark.HEAD_BYTES)
    except OSError:
        return b""


def _head(file: Path) -> Mark | None:
    fields = head_mark.read_slots(_read_head(file))
    if fields is None:
        return None
    try:
        return Mark(str(fields["epoch"]), int(fields["revision"]), int(fields["high_water"]))
    except (KeyError, ValueError):
        return None


def _has_slots(file: Path) -> bool:
    """Whether the file was written with a mark in its head (an intact record name says so)."""
    return head_mark.NAME.encode("ascii") in _read_head(file)
