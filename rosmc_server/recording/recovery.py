"""What a resume could not recover, said once in the log and kept for ``rosmc status``."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from rosmc_server.core.views.vocabulary import counted
from rosmc_server.recording.damage import Damage, skipped_line
from rosmc_server.recording.high_water import LEASE, Mark, next_after_loss
from rosmc_server.recording.mark_recovery import RecoveredMark
from rosmc_server.recording.reader import LatestState
from rosmc_server.recording.revisions import Gap, RevisionRange

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
        lost_at_end: Acknowledged revisions missing from the journal's end: its revision
            mark (:mod:`.high_water`) names a later one than any the journal holds.
        acknowledged: The last revision acknowledged before, as that mark says (-1: none).
        mark_alert: What became of the revision mark, when one copy stood in for the other
            or none read (see :mod:`.mark_recovery`); "" otherwise.
    """

    path: Path
    damage: tuple[Damage, ...]
    gaps: tuple[Gap, ...]
    resumed_at: int
    next_revision: int
    written_to: Path
    lost_at_end: int = 0
    acknowledged: int = -1
    mark_alert: str = ""
    mark_lost: bool = False

    @classmethod
    def of(
        cls,
        path: Path,
        damage: tuple[Damage, ...],
        latest: LatestState,
        written_to: Path,
        mark: Mark | RecoveredMark | None = None,
    ) -> ResumeReport:
        """The report of a resume that rebuilt ``latest`` from the journal at ``path``,
        whose revision mark (:mod:`.high_water`) was ``mark``."""
        recovered = mark if isinstance(mark, RecoveredMark) else RecoveredMark(mark)
        mark = recovered.mark
        end = latest.next_revision - 1  # the highest revision the journal holds
        lost_at_end = max(0, mark.revision - end) if mark is not None else 0
        next_revision = latest.next_revision
        if lost_at_end:  # which revisions went out after the end is unknown: above the lease
            next_revision = next_after_loss(mark, next_revision)
        mark_alert = recovered.alert
        mark_lost = recovered.lost and end > 0  # else only the first snapshot: nothing went out
        if mark_lost:  # no copy of the mark: a whole lease above the journal's end
            next_revision = max(next_revision, end + LEASE + 1)
            mark_alert += f"; revisions go on from r{next_revision}, a lease above its end"
        elif recovered.lost:
            mark_alert = ""
        acknowledged = mark.revision if mark is not None else -1
        return cls(
            path, damage, latest.gaps, latest.revision, next_revision, written_to, lost_at_end,
            acknowledged, mark_alert, mark_lost,
        )  # fmt: skip

    @property
    def clean(self) -> bool:
        """Whether the journal was read without damage or lost revisions."""
        return not self.damage and not self.gaps and not self.lost_at_end

    @property
    def history_lost(self) -> bool:
        """Whether revisions were lost or the mark had to be guessed: the mission's history
        starts a new epoch."""
        return self.lost > 0 or self.mark_lost

    @property
    def lost(self) -> int:
        """How many revisions cannot be rebuilt."""
        return sum(gap.revisions.count for gap in self.gaps) + self.lost_at_end

    def _end_line(self) -> str:
        if not self.lost_at_end:
            return ""
        return (
            f"{self._end_range()} lost from its end (the journal stops before the last "
            f"acknowledged revision, r{self.acknowledged})"
        )

    def _end_range(self) -> RevisionRange:
        return RevisionRange(self.acknowledged - self.lost_at_end + 1, self.acknowledged)

    def log_line(self) -> str:
        """The one ERROR line for the log: damaged offsets, lost revisions, where it goes on."""
        if self.clean:
            return self.mark_alert
        line = "; ".join(
            part
            for part in (skipped_line(self.path, self.damage, self.gaps), self._end_line())
            if part
        )
        if not self.damage and not self.gaps:
            line = f"journal {self.path}: {line}"
        if self._mission_lost():
            line += (
                f"; the mission resumed at r{self.resumed_at}, next revision r{self.next_revision}"
            )
        line = f"{line}; the journal goes on in {self.written_to.name}"
        return "; ".join(part for part in (line, self.mark_alert) if part)

    def alert(self) -> str:
        """One line for ``rosmc status`` ("" if the resume recovered everything)."""
        return "; ".join(a for a in (self._loss_alert(), self.mark_alert) if a)

    def _loss_alert(self) -> str:
        if self.clean:
            return ""
        if not self.gaps and not self.lost_at_end:
            count = len(self.damage)
            return (
                f"journal: {counted(count, 'damaged byte range')} skipped at "
                f"resume, no revision lost, see {self.path}"
            )
        ranges = [str(gap.revisions) for gap in self.gaps]
        if self.lost_at_end:
            ranges.append(str(self._end_range()))
        shown = ", ".join(ranges[:SHOWN])
        if len(ranges) > SHOWN:
            shown += ", ..."
        if self._mission_lost():
            how = f"the mission resumed at r{self.resumed_at}, next revision r{self.next_revision}"
        else:
            how = f"the mission is intact from the snapshot of r{self.gaps[-1].resumed_at}"
        lost = counted(self.lost, "revision")
        return f"journal: {lost} lost at resume ({shown}: {how}), see {self.path}"

    def _mission_lost(self) -> bool:
        return bool(self.lost_at_end) or (bool(self.gaps) and self.gaps[-1].resumed_at is None)
