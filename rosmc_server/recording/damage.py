"""Damaged bytes found in a journal, and the one line that tells a person about them."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

from rosmc_server.recording.revisions import Gap, RevisionRange

SHOWN = 4
"""Damaged ranges named one by one in a line; the rest are counted."""


@dataclass(frozen=True)
class Damage:
    """Bytes of a journal file that do not read as intact records and were skipped.

    Attributes:
        path: The file (one part of the journal).
        start: Offset of the first damaged byte.
        end: Offset just after the last damaged byte.
        what: What was found there, one phrase.
        kept: Only a field around an intact record was damaged (its length, say); the
            record itself was kept.
    """

    path: Path
    start: int
    end: int
    what: str
    kept: bool = False

    def __str__(self) -> str:
        return f"bytes {self.start}..{self.end - 1} of {self.path.name} ({self.what})"


def skipped_line(
    path: Path,
    damage: Sequence[Damage],
    gaps: Sequence[Gap] = (),
    missing: Sequence[RevisionRange] = (),
) -> str:
    """One line saying what reading ``path`` skipped; "" if it skipped nothing.

    Args:
        path: The journal (as the user named it).
        damage: The damaged byte ranges.
        gaps: Revisions whose mission cannot be rebuilt (for tools that rebuild it).
        missing: Revisions whose event is not in the output (for tools that copy records).
    """
    parts = []
    if damage:
        shown = ", ".join(str(d) for d in damage[:SHOWN])
        more = f" and {len(damage) - SHOWN} more ranges" if len(damage) > SHOWN else ""
        parts.append(f"skipped damaged {shown}{more}")
    parts += [str(gap) for gap in gaps]
    if missing:
        count = sum(r.count for r in missing)
        names = ", ".join(str(r) for r in missing[:SHOWN])
        more = ", ..." if len(missing) > SHOWN else ""
        parts.append(
            f"revision {names} has no event"
            if count == 1
            else f"{count} revisions have no event ({names}{more})"
        )
    return f"journal {path}: " + "; ".join(parts) if parts else ""
