"""Undo and redo of this window's own edits (Ctrl+Z, Ctrl+Shift+Z, Edit menu).

The two actions over the shared :class:`~rosmc_server.core.live.edit_history.EditHistory`
(rviz keeps one too, by the same rule): an accepted request whose kind is an edit can be
undone, and a Duplicate's copies are joined into one entry; undo asks the server to undo
the newest (``undo_edit``, against the revision shown), redo undoes that undo. A refusal
by the mission rules (the skills were sent since, someone changed them) drops the entry
and the message area shows the server's sentence; a conflict or no answer keeps it, and
Undo stays offered; the message area says each answer once, as for any request.
"""

from __future__ import annotations

from collections.abc import Callable

from python_qt_binding.QtCore import QObject
from python_qt_binding.QtWidgets import QWidget

from rosmc_server.core.live.edit_history import EditHistory, Failure, Step

from ..core.mission_view import MissionView
from ..core.requests import Answer, Request, ask
from .actions import CommandActions


class UndoHistory(QObject):  # type: ignore[misc]
    """The undo and redo actions of one command window.

    Args:
        owner: The command widget (the actions' shortcuts work inside it).
        view: The mission as shown (for the base revision).
        send: Hands a request to the backend.
    """

    def __init__(
        self,
        owner: QWidget,
        view: MissionView,
        send: Callable[[Request], None],
    ) -> None:
        super().__init__(owner)
        self._view = view
        self._send = send
        self.edits = EditHistory()
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
        revision = getattr(answer.value, "revision", None)
        if not answer.ok or revision is None:
            return ""
        what = answer.request.what or answer.request.operation.replace("_", " ")
        if not self.edits.done(answer.request.kind, int(revision), what):
            return ""
        self._update()
        return "Ctrl+Z undoes it"

    def join(self, revisions: list[int], what: str) -> None:
        """Make this window's newest edits, which produced ``revisions`` (oldest first), one
        entry called ``what``: one undo takes them all back (the server still records each)."""
        if self.edits.join(revisions, what):
            self._update()

    def undo(self) -> None:
        """Ask the server to undo this window's newest edit."""
        self._ask(redo=False)

    def redo(self) -> None:
        """Ask the server to undo this window's newest undo (the edit comes back)."""
        self._ask(redo=True)

    def _ask(self, *, redo: bool) -> None:
        step = None if self.read_only else self.edits.begin(redo=redo, seen=self._view.revision)
        if step is not None:
            self._update()
            self._send_undo(step, step.next_revision)

    def _send_undo(self, step: Step, revision: int) -> None:
        def answered(answer: Answer) -> None:
            self._answered(step, answer)

        pick = ask(lambda c: c.undo_edit, step.words, step.base_revision, answered)
        self._send(pick(revision))

    def _answered(self, step: Step, answer: Answer) -> None:
        if answer.ok:
            following = self.edits.accepted(step, int(answer.value.revision))
            if following is not None:  # joined edits: the next one back
                self._send_undo(step, following)
                return
        else:
            failure = (
                Failure.CONFLICT
                if answer.conflict
                else Failure.UNREACHABLE
                if answer.unreachable
                else Failure.REFUSED
            )
            # The message area says the answer once, as for any request; the entry is
            # kept (Undo stays offered) on a conflict or no answer.
            self.edits.failed(step, failure, answer.error)
        self._update()

    def set_read_only(self, read_only: bool) -> None:
        """A window that follows a replay undoes nothing."""
        self.read_only = read_only
        self._update()

    def _update(self) -> None:
        free = not self.edits.busy and not self.read_only
        undo, redo = self.edits.next_undo(), self.edits.next_redo()
        self.undo_action.setEnabled(free and undo is not None)
        self.redo_action.setEnabled(free and redo is not None)
        self.undo_action.setText(f"&Undo {undo.what}" if undo else "&Undo")
        self.redo_action.setText(f"&Redo {redo.what}" if redo else "&Redo")
