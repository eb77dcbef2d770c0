"""What a resume could not recover, said once in the log and kept for ``rosmc status``."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from rosmc_server.recording.damage import Damage, skipped_line
from rosmc_server.recording.reader import LatestState
from rosmc_server.recording.revisions import Gap

SHOWN = 3
"""Revision ranges named in the status line; the rest are counted."""


@dataclass(frozen=True)
class ResumeReport:
    """Damage and lost revisions a resume found in a journal.

    Attributes:
        path: The journal.
        damage: The damaged byte ranges skipped.
        gaps: The revisions that cannot be rebuilt.
        resumed_at: The revision the mission was rebuilt to.
        next_revision: The revision the next change gets: above every revision the journal
            holds, so no number an operator has seen is handed out again.
        written_to: The file the journal goes on in.
    """

    path: Path
    damage: tuple[Damage, ...]
    gaps: tuple[Gap, ...]
    resumed_at: int
    next_revision: int
    written_to: Path

    @classmethod
    def of(
        cls, path: Path, damage: tuple[Damage, ...], latest: LatestState, written_to: Path
    ) -> ResumeReport:
        """The report of a resume that rebuilt ``latest`` from the journal at ``path``."""
        return cls(path, damage, latest.gaps, latest.revision, latest.next_revision, written_to)

    @property
    def clean(self) -> bool:
        """Whether the journal was read without damage or lost revisions."""
        return not self.damage and not self.gaps

    @property
    def lost(self) -> int:
        """How many revisions cannot be rebuilt."""
        return sum(gap.revisions.count for gap in self.gaps)

    def log_line(self) -> str:
        """The one ERROR line for the log: damaged offsets, lost revisions, where it goes on."""
        if self.clean:
            return ""
        line = skipped_line(self.path, self.damage, self.gaps)
        if self._mission_lost():
            line += (
                f"; the mission resumed at r{self.resumed_at}, next revision r{self.next_revision}"
            )
        return f"{line}; the journal goes on in {self.written_to.name}"

    def alert(self) -> str:
        """One line for ``rosmc status`` ("" if the resume recovered everything)."""
        if self.clean:
            return ""
        if not self.gaps:
            ranges = len(self.damage)
            return (
                f"journal: {ranges} damaged byte range{'s' if ranges > 1 else ''} skipped at "
                f"resume, no revision lost, see {self.path}"
            )
        shown = ", ".join(str(gap.revisions) for gap in self.gaps[:SHOWN])
        if len(self.gaps) > SHOWN:
            shown += ", ..."
        if self._mission_lost():
            how = f"the mission resumed at r{self.resumed_at}, next revision r{self.next_revision}"
        else:
            how = f"the mission is intact from the snapshot of r{self.gaps[-1].resumed_at}"
        lost = f"{self.lost} revision{'s' if self.lost > 1 else ''}"
        return f"journal: {lost} lost at resume ({shown}: {how}), see {self.path}"

    def _mission_lost(self) -> bool:
        return bool(self.gaps) and self.gaps[-1].resumed_at is None
