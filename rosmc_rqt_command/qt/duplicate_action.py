"""Duplicate (Ctrl+D, task context menu): copies of the selected planned skills after them.

The mission server adds one skill per request, so the copies are sent one after another,
each once the one before was accepted (so each is made against the previous one's
revision and lands right after it); a refusal stops the rest and is said. The window's
undo history then holds them as one entry (one Ctrl+Z takes every copy back). The copies
are selected once shown, so Ctrl+D again copies them again.
"""

from __future__ import annotations

from collections.abc import Callable

from python_qt_binding.QtCore import QObject
from python_qt_binding.QtWidgets import QWidget

from rosmc_server.core import InvalidRequest
from rosmc_server.core.live.edit_history import EditKind

from ..core.duplicating import Copy, copies
from ..core.mission_view import MissionView
from ..core.requests import Answer, Request, ask
from .actions import CommandActions


class DuplicateAction(QObject):  # type: ignore[misc]
    """The Duplicate action of one command window.

    Args:
        owner: The command widget (the shortcut works inside it).
        view: The mission as shown.
        selected: The ids of the selected skills.
        send: Hands a request to the backend.
        select: Selects skills by id once they are shown.
        say: Puts a sentence in the message area (with its level).
        read_only: Whether the window follows a replay (nothing can be duplicated).
        join: Makes the edits that produced these revisions one undo entry.
    """

    def __init__(
        self,
        owner: QWidget,
        view: MissionView,
        selected: Callable[[], list[str]],
        send: Callable[[Request], None],
        select: Callable[[list[str]], None],
        say: Callable[[str, str], None],
        read_only: Callable[[], bool],
        join: Callable[[list[int], str], None],
    ) -> None:
        super().__init__(owner)
        self._view = view
        self._selected = selected
        self._send = send
        self._select = select
        self._say = say
        self._read_only = read_only
        self._join = join
        self.action = CommandActions.make(
            owner,
            "Duplicate",
            "Ctrl+D",
            "Add copies of the selected planned skills after them (same parameters and markers)",
            "duplicate",
        )
        self.action.triggered.connect(self._on_action_triggered)
        self.update()

    def update(self) -> None:
        """Enable the action when the selection can be duplicated."""
        if self._read_only():
            self.action.setEnabled(False)
            return
        try:
            copies(self._view, self._view.skills(self._selected()))
        except InvalidRequest:
            self.action.setEnabled(False)
            return
        self.action.setEnabled(True)

    def _on_action_triggered(self, _checked: bool = False) -> None:
        try:
            planned = copies(self._view, self._view.skills(self._selected()))
        except InvalidRequest as error:
            self._say(f"Not duplicated: {error}.", "warning")
            return
        what = f"duplicate {len(planned)} skills on {planned[0].agent}"
        self._next(planned, [], [], self._view.revision, what)

    def _next(
        self, planned: list[Copy], made: list[str], revisions: list[int], seen: int, what: str
    ) -> None:
        if not planned:
            self._join(revisions, what)
            self._select(made)
            return
        copy, rest = planned[0], planned[1:]

        def sent(answer: Answer) -> None:
            if answer.ok:
                revision = int(answer.value.revision)
                ids = [*made, answer.value.skill_id]
                self._next(rest, ids, [*revisions, revision], revision, what)

        one = f"duplicate {copy.label or copy.skill} on {copy.agent}"
        call = ask(lambda c: c.add_skill, one, seen, sent, EditKind.ADD_SKILL)
        self._send(
            call(
                copy.agent,
                copy.skill,
                copy.params,
                bindings=copy.bindings,
                label=copy.label,
                index=copy.index,
                timeout=copy.timeout,
                max_retries=copy.max_retries,
            )
        )
