"""Undo and redo of one GUI's own edits, with one rule for the command GUI and rviz.

A GUI tells :class:`EditHistory` of every request the server accepted, with the request's
:class:`EditKind` (None for a request that is not an edit: synchronize, control, load, ...);
only edits are kept. Undo asks the server to undo the newest (``undo_edit``: the inverse
as a new revision); redo undoes that undo. The rule, whichever GUI asks:

* one undo or redo at a time: the next waits for the answer;
* an entry may stand for several edits (:meth:`EditHistory.join`: a Duplicate's copies,
  each its own change on the server): one undo takes them all back, newest first, one
  ``undo_edit`` after the other;
* it is made against the revision the operator saw (:attr:`Step.base_revision`), so the
  server refuses it if someone changed the mission since;
* refused as a conflict (someone changed the mission first) or unanswered (the server is
  not reachable), the entry is kept where it was, to be tried again, and the sentence says
  so; refused by the mission rules (the skills were sent since, someone edited them), the
  entry is dropped and the sentence gives the server's reason.

No Qt and no rospy: safe to use from several threads (rviz answers on its client's thread).
"""

from __future__ import annotations

import enum
import threading
from dataclasses import dataclass

from ..errors import ServerUnavailable, StaleRevision


class EditKind(enum.Enum):
    """An operator request that changes the blueprint, a barrier or a task marker: what
    undo can take back (the server keeps the inverse of exactly these)."""

    ADD_SKILL = enum.auto()
    EDIT_SKILL = enum.auto()
    DELETE_SKILLS = enum.auto()
    REORDER_SKILLS = enum.auto()
    ADD_BARRIER = enum.auto()
    DELETE_BARRIER = enum.auto()
    ADD_MARKER = enum.auto()
    MOVE_MARKER = enum.auto()
    RENAME_MARKER = enum.auto()
    DELETE_MARKER = enum.auto()


class Failure(enum.Enum):
    """Why an undo or redo did not happen."""

    CONFLICT = "the mission changed before the server got it"
    UNREACHABLE = "the mission server did not answer"
    REFUSED = "the server refused it"


def failure_of(error: BaseException) -> Failure:
    """The :class:`Failure` a client's error stands for."""
    if isinstance(error, StaleRevision):
        return Failure.CONFLICT
    if isinstance(error, ServerUnavailable):
        return Failure.UNREACHABLE
    return Failure.REFUSED


@dataclass(frozen=True)
class Entry:
    """The revisions an edit (or an undo) produced, newest first (several for joined
    edits), and what it did, in words."""

    revisions: tuple[int, ...]
    what: str

    @property
    def revision(self) -> int:
        """The newest revision (the one undo takes back first)."""
        return self.revisions[0]


@dataclass
class Step:
    """An undo or redo on its way: ask the server to undo :attr:`next_revision` against
    :attr:`base_revision`, the revision the operator saw, then the next (joined edits)."""

    entry: Entry
    redo: bool
    base_revision: int | None
    done: list[int]  # the revisions the undos of this step produced so far

    @property
    def words(self) -> str:
        """What the step does ("undo move 'Pose 1'")."""
        return f"{'redo' if self.redo else 'undo'} {self.entry.what}"

    @property
    def next_revision(self) -> int:
        """The revision to undo next."""
        return self.entry.revisions[len(self.done)]

    @property
    def left(self) -> tuple[int, ...]:
        """The revisions not undone yet, newest first."""
        return self.entry.revisions[len(self.done) :]


class EditHistory:
    """The undo and redo stacks of one GUI (see the module's rule)."""

    def __init__(self) -> None:
        self._lock = threading.Lock()
        self._undo: list[Entry] = []
        self._redo: list[Entry] = []
        self._step: Step | None = None

    def done(self, kind: EditKind | None, revision: int, what: str) -> bool:
        """The server accepted a request of ``kind`` at ``revision``; True if it is an edit
        (undo can take it back; nothing is left to redo)."""
        if kind is None:
            return False
        with self._lock:
            self._undo.append(Entry((revision,), what))
            self._redo.clear()
        return True

    def join(self, revisions: list[int], what: str) -> bool:
        """Make the newest edits, which produced ``revisions`` (oldest first), one entry
        called ``what``; False (nothing changes) if another edit came in between."""
        count = len(revisions)
        with self._lock:
            newest = self._undo[-count:] if count >= 2 else []
            if [entry.revisions for entry in newest] != [(r,) for r in revisions]:
                return False
            del self._undo[-count:]
            self._undo.append(Entry(tuple(reversed(revisions)), what))
        return True

    def begin(self, *, redo: bool, seen: int | None) -> Step | None:
        """Take the newest edit (``redo``: the newest undo) to send against ``seen``; None if
        there is none or a step is on its way."""
        with self._lock:
            stack = self._redo if redo else self._undo
            if not stack or self._step is not None:
                return None
            self._step = Step(stack.pop(), redo, seen, [])
            return self._step

    def accepted(self, step: Step, revision: int) -> int | None:
        """One undo of ``step`` was done at ``revision``; the next revision to undo (joined
        edits), or None: the step is over and the other stack can take it back."""
        with self._lock:
            step.done.append(revision)
            if step.left and self._step is step:
                return step.next_revision
            self._end(step)
            return None

    def failed(self, step: Step, failure: Failure, reason: str = "") -> str:
        """``step`` did not happen (or only partly); returns the sentence to show (kept or
        dropped, and why)."""
        kept = failure is not Failure.REFUSED
        with self._lock:
            if self._end(step) and kept:
                origin = self._redo if step.redo else self._undo
                origin.append(Entry(step.left, step.entry.what))
        why = reason or failure.value
        if kept:
            return f"Could not {step.words} ({why}); it is kept: try again"
        return f"Could not {step.words}: {why}"

    def _end(self, step: Step) -> bool:
        """End ``step`` (lock held): what it undid goes to the other stack. False if it was
        forgotten meanwhile (:meth:`clear`: its revisions name another history)."""
        if self._step is not step:
            return False
        self._step = None
        if step.done:
            other = self._undo if step.redo else self._redo
            other.append(Entry(tuple(reversed(step.done)), step.entry.what))
        return True

    @property
    def busy(self) -> bool:
        """An undo or redo is on its way."""
        with self._lock:
            return self._step is not None

    def next_undo(self) -> Entry | None:
        """What undo would take back now (None: nothing)."""
        with self._lock:
            return self._undo[-1] if self._undo else None

    def next_redo(self) -> Entry | None:
        """What redo would bring back now (None: nothing)."""
        with self._lock:
            return self._redo[-1] if self._redo else None

    def newest_above(self, revision: int) -> bool:
        """Some entry names a revision above ``revision`` (a snapshot older than this GUI's
        own edits: a new server, whose revisions are another history)."""
        with self._lock:
            return any(entry.revision > revision for entry in (*self._undo, *self._redo))

    def clear(self) -> None:
        """Forget everything (a new mission, or a new server)."""
        with self._lock:
            self._undo.clear()
            self._redo.clear()
            self._step = None
