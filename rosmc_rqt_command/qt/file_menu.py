"""New, open and save: mission files on this computer or on the mission server's.

A local file is read here and sent as a document (``load_mission(document=...)``), or
written here from the server's document (``save_mission()``); a server file is named by
its path on the server's host. Before New or Open replaces a mission that changed since it
was last saved or loaded, the operator is asked whether to save it first.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from pathlib import Path

from python_qt_binding.QtWidgets import QFileDialog, QInputDialog, QMessageBox, QWidget

from rosmc_server.core import Barrier, SkillInstance, TaskMarker

from ..core.mission_view import MissionView
from ..core.requests import Answer, Request, ask
from .actions import CommandActions
from .message_area import MessageArea

FILTER = "Mission files (*.yaml *.yml);;All files (*)"
Send = Callable[[Request], None]


Content = tuple[
    str,
    tuple[tuple[str, Sequence[SkillInstance]], ...],
    tuple[Barrier, ...],
    tuple[TaskMarker, ...],
]


def mission_of(view: MissionView) -> Content:
    """The mission as it is now (skills are immutable values; only the task lists are copied)."""
    tasks = tuple((agent, tuple(task.skills)) for agent, task in view.agents.items())
    return (view.library_name, tasks, view.barriers, tuple(view.markers.values()))


def mission_fingerprint(mission: Content) -> tuple[object, ...]:
    """What a mission file keeps of a mission (ignores statuses and robot progress)."""
    library, tasks, barriers, markers = mission
    steps = tuple(
        (
            agent,
            tuple((s.skill, s.label, repr(dict(s.params)), repr(dict(s.bindings))) for s in skills),
        )
        for agent, skills in tasks
    )
    barrier_sets = tuple(sorted(tuple(sorted(b.skill_ids)) for b in barriers))
    return (library, steps, barrier_sets, tuple(sorted(repr(m) for m in markers)))


class FileController:
    """The File menu's actions; keeps where the mission was last saved."""

    def __init__(
        self,
        parent: QWidget,
        actions: CommandActions,
        view: MissionView,
        messages: MessageArea,
        send: Send,
    ) -> None:
        self._parent = parent
        self._view = view
        self._messages = messages
        self._send = send
        self.location: tuple[str, str] | None = None  # ("local" | "server", path)
        self._saved: Content | None = None
        self._after_save: Callable[[], None] | None = None  # closes the window once saved
        self.ask: Callable[[str], str] = self._ask_save_changes
        handlers = {
            "new": self.new_mission,
            "open": self._on_open_triggered,
            "open_server": self._on_open_server_triggered,
            "save": self.save,
            "save_as": self._on_save_as_triggered,
            "save_server": self._on_save_server_triggered,
        }
        for name, handler in handlers.items():
            actions.file[name].triggered.connect(lambda _=False, h=handler: h())

    # -- unsaved changes ------------------------------------------------------------------------
    def mark_saved(self) -> None:
        """The mission as it is now counts as saved (after a load, save or new mission)."""
        self._saved = mission_of(self._view)

    @property
    def dirty(self) -> bool:
        """The mission changed since it was last saved, loaded or started anew."""
        if self._saved is None:
            return any(view.skills for view in self._view.agents.values())
        now = mission_of(self._view)
        return now != self._saved and mission_fingerprint(now) != mission_fingerprint(self._saved)

    def confirm_discard(self, doing: str) -> bool:
        """Ask to save unsaved changes before ``doing``; False if the operator cancels."""
        if not self.dirty:
            return True
        answer = self.ask(doing)
        if answer == "save":
            self.save()
            return True
        return answer == "discard"

    def may_close(self, close: Callable[[], None]) -> bool:
        """Whether the window may close now (asking about unsaved changes first).

        Save keeps the window open until the server's answer: ``close`` is called once
        the mission is saved; if saving fails (or no file is chosen) the window stays
        open and the message area says why.
        """
        if not self.dirty:
            return True
        answer = self.ask("closing")
        if answer == "save":
            self._after_save = close
            if not self.save():
                self._after_save = None
                self._messages.say("Not closed: the mission was not saved.", "warning")
        return answer == "discard"

    def _ask_save_changes(self, doing: str) -> str:
        box = QMessageBox(self._parent)
        box.setIcon(QMessageBox.Question)
        box.setWindowTitle("Unsaved changes")
        box.setText(f"The mission has changes that are not saved. Save them before {doing}?")
        box.setStandardButtons(QMessageBox.Save | QMessageBox.Discard | QMessageBox.Cancel)
        box.setDefaultButton(QMessageBox.Save)
        choice = box.exec_()
        return {QMessageBox.Save: "save", QMessageBox.Discard: "discard"}.get(choice, "cancel")

    # -- operations (what the dialogs lead to; tests call them directly) ---------------------------
    def new_mission(self) -> None:
        """Start an empty mission (after asking about unsaved changes)."""
        if self.confirm_discard("starting a new mission"):
            self._send(
                ask(
                    lambda c: c.new_mission,
                    "start a new mission",
                    self._view.revision,
                    self._on_replaced,
                )()
            )

    def open_local(self, path: str) -> None:
        """Load a mission file from this computer."""
        try:
            document = Path(path).read_text(encoding="utf-8")
        except (OSError, UnicodeDecodeError) as error:
            self._messages.say(f"Cannot read {path}: {error}.", "error")
            return
        self._send(
            ask(
                lambda c: c.load_mission,
                f"open {path}",
                self._view.revision,
                lambda a: self._on_loaded(a, ("local", path)),
            )(document=document)
        )

    def open_server(self, path: str) -> None:
        """Load a mission file from the server's computer."""
        self._send(
            ask(
                lambda c: c.load_mission,
                f"open {path} on the server",
                self._view.revision,
                lambda a: self._on_loaded(a, ("server", path)),
            )(path=path)
        )

    def save(self) -> bool:
        """Save where the mission was last saved or opened (else ask where); False if not sent."""
        if self.location is None:
            return self._on_save_as_triggered()
        if self.location[0] == "local":
            self.save_local(self.location[1])
        else:
            self.save_server(self.location[1])
        return True

    def save_local(self, path: str) -> None:
        """Save the mission to a file on this computer."""
        fingerprint = mission_of(self._view)
        self._send(
            ask(
                lambda c: c.save_mission,
                f"save to {path}",
                on_answer=lambda a: self._on_saved_document(a, path, fingerprint),
            )()
        )

    def save_server(self, path: str) -> None:
        """Save the mission to a file on the server's computer."""
        fingerprint = mission_of(self._view)
        self._send(
            ask(
                lambda c: c.save_mission,
                f"save to {path} on the server",
                on_answer=lambda a: self._on_saved(a, ("server", path), fingerprint),
            )(path)
        )

    # -- answers ----------------------------------------------------------------------------
    def _on_replaced(self, answer: Answer) -> None:
        if answer.ok:
            self.location = None
            self._saved = None

    def _on_loaded(self, answer: Answer, location: tuple[str, str]) -> None:
        if answer.ok:
            self.location = location
            self._saved = None
            # The loaded mission counts as saved once it is shown; its update may have
            # arrived before this answer, or may still be on its way.
            self._mark_at = int(getattr(answer.value, "revision", self._view.revision))
            self.on_mission_shown()

    _mark_at: int | None = None

    def on_mission_shown(self) -> None:
        """Called after each update: a freshly loaded mission counts as saved."""
        if self._mark_at is not None and self._view.revision >= self._mark_at:
            self._mark_at = None
            self.mark_saved()

    def _on_saved_document(self, answer: Answer, path: str, fingerprint: Content) -> None:
        if answer.ok:
            try:
                Path(path).write_text(answer.value.document, encoding="utf-8")
            except OSError as error:
                self._messages.say(f"Cannot write {path}: {error}.", "error")
                self._closing_failed()
                return
            self._messages.say(f"Saved the mission to {path}.", "ok")
        self._on_saved(answer, ("local", path), fingerprint)

    def _on_saved(self, answer: Answer, location: tuple[str, str], fingerprint: Content) -> None:
        if not answer.ok:
            self._closing_failed()
            return
        self.location = location
        self._saved = fingerprint
        close, self._after_save = self._after_save, None
        if close is not None:
            close()

    def _closing_failed(self) -> None:
        if self._after_save is not None:
            self._after_save = None
            self._messages.say("Not closed: the mission was not saved (see above).", "warning")

    # -- dialogs ----------------------------------------------------------------------------
    def _on_open_triggered(self) -> None:
        if not self.confirm_discard("opening another mission"):
            return
        path, _ = QFileDialog.getOpenFileName(self._parent, "Open mission file", "", FILTER)
        if path:
            self.open_local(path)

    def _on_open_server_triggered(self) -> None:
        if not self.confirm_discard("opening another mission"):
            return
        path, ok = QInputDialog.getText(
            self._parent, "Open file on server", "Path of the mission file on the server:"
        )
        if ok and path.strip():
            self.open_server(path.strip())

    def _on_save_as_triggered(self) -> bool:
        path, _ = QFileDialog.getSaveFileName(self._parent, "Save mission file", "", FILTER)
        if path:
            self.save_local(path if Path(path).suffix else f"{path}.yaml")
        return bool(path)

    def _on_save_server_triggered(self) -> None:
        path, ok = QInputDialog.getText(
            self._parent, "Save on server", "Path of the mission file on the server:"
        )
        if ok and path.strip():
            self.save_server(path.strip())
