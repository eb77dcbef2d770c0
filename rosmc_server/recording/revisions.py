"""Which revisions of a journal can be rebuilt, and which are lost.

A journal holds full snapshots and one event per revision. The mission at a
revision is rebuilt from a snapshot and the events that follow it one by one;
an event whose predecessor is missing (a damaged record, a lost change) cannot
be applied, so every revision from the missing one on is lost until the next
snapshot. :class:`RevisionWalk` makes that decision record by record, in file
order, for the server's resume (numbers only) and for the review tools (which
rebuild the content). It also keeps events that arrived before they could be
applied: a periodic snapshot is often journaled a moment after events newer
than itself, and those events still count once it arrives.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable
from dataclasses import dataclass
from itertools import pairwise
from typing import Generic, TypeVar

S = TypeVar("S")
E = TypeVar("E")


@dataclass(frozen=True)
class RevisionRange:
    """Revisions ``first`` to ``last``, both included."""

    first: int
    last: int

    @property
    def count(self) -> int:
        """How many revisions the range holds."""
        return self.last - self.first + 1

    def __str__(self) -> str:
        return f"r{self.first}" if self.first == self.last else f"r{self.first}..r{self.last}"


@dataclass(frozen=True)
class Gap:
    """Revisions whose mission cannot be rebuilt from the journal.

    Attributes:
        revisions: The revisions lost.
        resumed_at: Revision of the snapshot the mission is rebuilt from after the gap;
            None if no snapshot follows (the lost revisions run to the newest one seen).
        cause: Why the first revision is lost, one phrase ("is missing", ...).
    """

    revisions: RevisionRange
    resumed_at: int | None
    cause: str = "is missing"

    def __str__(self) -> str:
        plural = "s" if self.revisions.count > 1 else ""
        text = f"revision{plural} {self.revisions} cannot be rebuilt"
        if self.revisions.count > 1:
            text = f"{self.revisions.count} {text}"
        if self.cause != "is missing":
            text += f" (r{self.revisions.first} {self.cause})"
        if self.resumed_at is not None:
            return f"{text}; the mission continues from the snapshot of r{self.resumed_at}"
        return text


class RevisionWalk(Generic[S, E]):
    """Follows a journal's snapshots and events in file order.

    ``restart(snapshot, replacing_event)`` is called whenever the mission (re)starts
    from a snapshot (``replacing_event`` is the ``MISSION_REPLACED`` event it belongs
    to, or None); ``apply(event)`` for each event that is the next revision, returning
    False if it could not be applied; ``covered(snapshot)`` (optional) for a snapshot of a
    revision the mission already reached. Call :meth:`finish` after the last record.

    Attributes:
        current: The revision the mission is at (None before the first snapshot).
        gaps: The revisions that cannot be rebuilt, oldest first.
        highest: The highest revision any record holds (-1 for none), leaving out a
            replacement the journal ends with before its snapshot (never acknowledged).
        unacknowledged: Revision of that replacement, if the journal ends with one.
    """

    def __init__(
        self,
        restart: Callable[[S, E | None], None],
        apply: Callable[[E], bool],
        covered: Callable[[S], None] | None = None,
    ) -> None:
        self._restart_cb = restart
        self._apply_cb = apply
        self._covered_cb = covered
        self.current: int | None = None
        self.gaps: list[Gap] = []
        self.highest = -1
        self.unacknowledged: int | None = None
        self._broken: tuple[int, str] | None = None  # first revision lost, and why
        self._pending: tuple[int, E] | None = None  # a replacement awaiting its snapshot
        self._waiting: dict[int, tuple[bool, E]] = {}  # events that do not follow yet
        self._top: list[int] = []  # the two highest revisions seen

    def snapshot(self, revision: int, item: S) -> None:
        """Take a snapshot record of ``revision``."""
        self._saw(revision)
        pending = self._pending
        if pending is not None and revision == pending[0]:
            self._restart(revision, item, pending[1])
        elif self.current is None or revision > self.current:
            self._restart(revision, item, None)
        elif self._covered_cb is not None:  # a periodic snapshot of a revision already rebuilt
            self._covered_cb(item)

    def event(self, revision: int, replaced: bool, item: E) -> None:
        """Take an event record of ``revision`` (``replaced``: a MISSION_REPLACED event)."""
        if self.current is not None and revision <= self.current:
            return  # already part of the mission (written before a late snapshot)
        self._saw(revision)
        if self._pending is not None and self._broken is None:
            self._broken = (self._pending[0], "replaced the mission, but its snapshot is missing")
            self._pending = None
        follows = self.current is not None and revision == self.current + 1
        if not follows or self._broken is not None:
            self._waiting.setdefault(revision, (replaced, item))
            if self.current is not None and self._broken is None:
                self._broken = (self.current + 1, "is missing")
            return
        self._apply(revision, replaced, item)
        self._advance()

    def finish(self) -> None:
        """Close the walk: a trailing replacement is left out, a trailing gap recorded."""
        if self._pending is not None:
            self.unacknowledged = self._pending[0]
            self.highest = max((r for r in self._top if r != self.unacknowledged), default=-1)
            self._pending = None
        if self._broken is None and self.current is not None and self._waiting:
            self._broken = (self.current + 1, "is missing")
        if self._broken is not None:
            first, cause = self._broken
            self.gaps.append(Gap(RevisionRange(first, max(first, self.highest)), None, cause))

    def _saw(self, revision: int) -> None:
        self.highest = max(self.highest, revision)
        if revision not in self._top:
            self._top = sorted([*self._top, revision])[-2:]

    def _restart(self, revision: int, item: S, replacing: E | None) -> None:
        first = self._first_missing()
        if first is not None and revision > first:
            cause = "is missing"
            if self._broken is not None:
                cause = self._broken[1]
            elif self._pending is not None:
                cause = "replaced the mission, but its snapshot is missing"
            self.gaps.append(Gap(RevisionRange(first, revision - 1), revision, cause))
        self.current, self._broken, self._pending = revision, None, None
        self._restart_cb(item, replacing)
        self._advance()

    def _first_missing(self) -> int | None:
        if self._broken is not None:
            return self._broken[0]
        if self._pending is not None:
            return self._pending[0]
        if self.current is not None:
            return self.current + 1
        # Before the first snapshot: events that came earlier cannot be rebuilt.
        return min(self._waiting, default=None)

    def _apply(self, revision: int, replaced: bool, item: E) -> None:
        if replaced:  # its content is only in the snapshot that follows it
            self._pending = (revision, item)
        elif self._apply_cb(item):
            self.current = revision
        else:
            self._broken = (revision, "does not apply")

    def _advance(self) -> None:
        """Apply the waiting events that now follow.

        The rest keep waiting without marking a gap yet: the events after a snapshot
        in the file may still bring the revision they need.
        """
        while self._broken is None and self._pending is None and self.current is not None:
            waiting = self._waiting.pop(self.current + 1, None)
            if waiting is None:
                break
            self._apply(self.current + 1, *waiting)
        current = -1 if self.current is None else self.current
        self._waiting = {r: e for r, e in self._waiting.items() if r > current}


def missing_revisions(revisions: Iterable[int]) -> list[RevisionRange]:
    """The ranges missing between the lowest and the highest of ``revisions``."""
    ordered = sorted(set(revisions))
    return [RevisionRange(low + 1, high - 1) for low, high in pairwise(ordered) if high > low + 1]
