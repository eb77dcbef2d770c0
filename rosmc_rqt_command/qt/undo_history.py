"""Undo and redo of this window's own edits (Ctrl+Z, Ctrl+Shift+Z, Edit menu).

The window keeps the revisions its accepted edits produced. Undo asks the server
to undo the newest (``undo_edit``: the inverse as a new revision); redo undoes that
undo. The server refuses, in one sentence, an edit whose skills were sent since or
that someone changed; the message area shows the sentence and the entry is dropped.
"""

from __future__ import annotations

from collections.abc import Callable

from python_qt_binding.QtCore import QObject
from python_qt_binding.QtWidgets import QWidget

from ..core.mission_view import MissionView
from ..core.requests import Answer, Request, ask
from .actions import CommandActions

# The window's requests whose effect undo can take back.
UNDOABLE = frozenset(
    {
        "add_skill",
        "edit_skill",
        "delete_skills",
        "reorder_skills",
        "add_barrier",
        "delete_barrier",
        "add_task_marker",
        "move_task_marker",
        "rename_task_marker",
        "delete_task_marker",
    }
)


class UndoHistory(QObject):  # type: ignore[misc]
    """The undo and redo stacks of one command window, and their two actions.

    Args:
        owner: The command widget (the actions' shortcuts work inside it).
        view: The mission as shown (for the base revision).
        send: Hands a request to the backend.
    """

    def __init__(self, owner: QWidget, view: MissionView, send: Callable[[Request], None]) -> None:
        super().__init__(owner)
        self._view = view
        self._send = send
        self._undo: list[tuple[int, str]] = []  # (revision an edit produced, what it did)
        self._redo: list[tuple[int, str]] = []  # (revision an undo produced, what it undid)
        # An entry made of several edits (see join): its revision -> the others', newest first.
        self._joined: dict[int, list[int]] = {}
        self._waiting = False  # one undo or redo at a time: the next needs its answer
        self.read_only = False
        self.undo_action = CommandActions.make(
            owner, "&Undo", "Ctrl+Z", "Undo your last edit", "undo"
        )
        self.redo_action = CommandActions.make(
            owner, "&Redo", "Ctrl+Shift+Z|Ctrl+Y", "Redo the edit you undid", "redo"
        )
        self.undo_action.triggered.connect(self.undo)
        self.redo_action.triggered.connect(self.redo)
        self._update()

    def note(self, answer: Answer) -> str:
        """Remember an accepted edit of this window; a hint for its message ("" if none)."""
        operation = answer.request.operation
        revision = getattr(answer.value, "revision", None)
        if not answer.ok or operation not in UNDOABLE or revision is None:
            return ""
        self._undo.append((int(revision), answer.request.what or operation.replace("_", " ")))
        self._redo.clear()
        self._update()
        return "Ctrl+Z undoes it"

    def join(self, revisions: list[int], what: str) -> None:
        """Make this window's newest edits, which produced ``revisions`` (oldest first), one
        entry called ``what``: one undo takes them all back (the server still records each)."""
        count = len(revisions)
        if count < 2 or [r for r, _ in self._undo[-count:]] != revisions:
            return  # another edit came in between: they stay separate
        del self._undo[-count:]
        self._push(self._undo, revisions[::-1], what)
        self._update()

    def undo(self) -> None:
        """Ask the server to undo this window's newest edit."""
        if self._undo and not self._waiting and not self.read_only:
            revision, what = self._undo.pop()
            revisions = [revision, *self._joined.pop(revision, [])]
            self._ask(revisions, f"undo {what}", self._redo, self._undo, what)

    def redo(self) -> None:
        """Ask the server to undo this window's newest undo (the edit comes back)."""
        if self._redo and not self._waiting and not self.read_only:
            revision, what = self._redo.pop()
            revisions = [revision, *self._joined.pop(revision, [])]
            self._ask(revisions, f"redo {what}", self._undo, self._redo, what)

    def _push(self, onto: list[tuple[int, str]], newest_first: list[int], what: str) -> None:
        onto.append((newest_first[0], what))
        if len(newest_first) > 1:
            self._joined[newest_first[0]] = newest_first[1:]

    def _ask(
        self,
        revisions: list[int],
        words: str,
        onto: list[tuple[int, str]],
        back: list[tuple[int, str]],
        what: str,
    ) -> None:
        """Undo ``revisions`` (newest first) one after another."""
        done: list[int] = []

        def answered(answer: Answer) -> None:
            if answer.ok:
                done.append(int(answer.value.revision))
                if len(done) < len(revisions):
                    send(revisions[len(done)])
                    return
            elif answer.conflict or answer.unreachable:
                self._push(back, revisions[len(done) :], what)  # not refused: try again later
            self._waiting = False
            if done:
                self._push(onto, done[::-1], what)
            self._update()

        def send(revision: int) -> None:
            self._send(ask(lambda c: c.undo_edit, words, self._view.revision, answered)(revision))

        self._waiting = True
        self._update()
        send(revisions[0])

    def set_read_only(self, read_only: bool) -> None:
        """A window that follows a replay undoes nothing."""
        self.read_only = read_only
        self._update()

    def _update(self) -> None:
        free = not self._waiting and not self.read_only
        self.undo_action.setEnabled(free and bool(self._undo))
        self.redo_action.setEnabled(free and bool(self._redo))
        self.undo_action.setText(f"&Undo {self._undo[-1][1]}" if self._undo else "&Undo")
        self.redo_action.setText(f"&Redo {self._redo[-1][1]}" if self._redo else "&Redo")
