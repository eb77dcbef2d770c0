"""Undo and redo of the edits made in this rviz (its menus, drags and tools).

Every marker's menu ends with ``Undo my last change`` and ``Redo``. The marker node keeps
the revisions its accepted edits produced; undo asks the server to undo the newest
(``undo_edit``: the inverse as a new revision), redo undoes that undo. The server refuses,
in one sentence, an edit whose skills were sent since or that someone else changed; the
entry is then dropped. The command GUI keeps its own history: each window undoes its own.
"""

from __future__ import annotations

import threading
from dataclasses import dataclass, field

Entry = tuple[int, str]  # (the revision an edit or undo produced, what it did)


@dataclass
class EditHistory:
    """The undo and redo stacks of one rviz (safe to use from several threads)."""

    _undo: list[Entry] = field(default_factory=list)
    _redo: list[Entry] = field(default_factory=list)
    _lock: threading.Lock = field(default_factory=threading.Lock)

    def done(self, revision: int, what: str) -> None:
        """An edit of this rviz was accepted at ``revision``: it can be undone; no redo."""
        with self._lock:
            self._undo.append((revision, what))
            self._redo.clear()

    def take_undo(self) -> Entry | None:
        """The newest edit to undo (taken off the stack), or None."""
        with self._lock:
            return self._undo.pop() if self._undo else None

    def take_redo(self) -> Entry | None:
        """The newest undo to take back (taken off the stack), or None."""
        with self._lock:
            return self._redo.pop() if self._redo else None

    def undone(self, revision: int, what: str) -> None:
        """An undo was accepted at ``revision``: redo can take it back."""
        with self._lock:
            self._redo.append((revision, what))

    def redone(self, revision: int, what: str) -> None:
        """A redo was accepted at ``revision``: undo can take it back again."""
        with self._lock:
            self._undo.append((revision, what))

    def newest_above(self, revision: int) -> bool:
        """Some entry names a revision above ``revision`` (a snapshot older than this rviz's
        own edits: a new server, whose revisions are another history)."""
        with self._lock:
            return any(entry[0] > revision for entry in (*self._undo, *self._redo))

    def clear(self) -> None:
        """Forget everything (a new mission, or a new server)."""
        with self._lock:
            self._undo.clear()
            self._redo.clear()
