"""The message area: standing warnings on top, then every answer and error as a sentence.

Nothing fails silently: each server answer, refusal, lost connection and local problem
lands here with its time, newest first, coloured by severity.
"""

from __future__ import annotations

import time
from collections.abc import Sequence

from python_qt_binding.QtCore import Signal
from python_qt_binding.QtGui import QBrush, QColor
from python_qt_binding.QtWidgets import (
    QHBoxLayout,
    QLabel,
    QListWidget,
    QListWidgetItem,
    QPushButton,
    QVBoxLayout,
    QWidget,
)

from .labels import never_widen

MAX_MESSAGES = 300
SEVERITY_COLOURS = {"info": "#1d1d1d", "ok": "#11632b", "warning": "#8a5a00", "error": "#b00020"}


class MessageArea(QWidget):  # type: ignore[misc]
    """Warnings and the log of messages.

    Under the warnings, one *Resume <robot>* button per robot holding after its lost-link
    policy (:meth:`show_holds`): the one action that frees it, next to the words.
    """

    resume_requested = Signal(str)  # the robot to resume

    def __init__(self, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.warnings_label = QLabel("")
        self.warnings_label.setObjectName("warnings")
        never_widen(self.warnings_label)  # a long warning wraps, the window keeps its width
        self.warnings_label.setStyleSheet(
            "QLabel { background:#fff3c4; border:1px solid #e0b000; padding:4px; }"
        )
        self.warnings_label.hide()
        self.hold_bar = QWidget()
        self.hold_bar.setObjectName("hold_bar")
        self._hold_row = QHBoxLayout(self.hold_bar)
        self._hold_row.setContentsMargins(0, 0, 0, 0)
        self._hold_row.addStretch(1)
        self.hold_buttons: dict[str, QPushButton] = {}
        self.hold_bar.hide()
        self.log = QListWidget()
        self.log.setObjectName("messages")
        self.log.setWordWrap(True)
        self.log.setAlternatingRowColors(True)
        layout = QVBoxLayout(self)
        layout.setContentsMargins(0, 0, 0, 0)
        layout.addWidget(self.warnings_label)
        layout.addWidget(self.hold_bar)
        layout.addWidget(self.log)
        self.warnings: list[str] = []

    def show_warnings(self, warnings: Sequence[str]) -> None:
        """Replace the standing warnings (hidden when there are none)."""
        if list(warnings) == self.warnings:
            return
        self.warnings = list(warnings)
        self.warnings_label.setText("<br>".join(f"⚠ {w}" for w in warnings))
        self.warnings_label.setVisible(bool(warnings))

    def set_read_only(self, read_only: bool) -> None:
        """Follow a replay: a robot held in the recording cannot be resumed from here."""
        self.hold_bar.setEnabled(not read_only)

    def show_holds(self, agents: Sequence[str]) -> None:
        """One *Resume <robot>* button per robot in ``agents`` (hidden when there is none)."""
        for agent in [a for a in self.hold_buttons if a not in agents]:
            self.hold_buttons.pop(agent).deleteLater()
        for agent in agents:
            if agent not in self.hold_buttons:
                button = QPushButton(f"Resume {agent}")
                button.setObjectName(f"warning_resume_{agent}")
                button.setToolTip(f"Let {agent} go on with its work (its barrier partners too)")
                button.clicked.connect(lambda _=False, a=agent: self.resume_requested.emit(a))
                self._hold_row.insertWidget(self._hold_row.count() - 1, button)
                self.hold_buttons[agent] = button
        self.hold_bar.setVisible(bool(agents))

    def say(self, text: str, severity: str = "info", detail: str = "") -> None:
        """Add one message (``severity``: info, ok, warning or error); ``detail`` (numbers
        for roboticists, e.g. the mission revision) goes in its tooltip."""
        item = QListWidgetItem(f"{time.strftime('%H:%M:%S')}  {text}")
        if detail:
            item.setToolTip(detail)
        item.setForeground(QBrush(QColor(SEVERITY_COLOURS.get(severity, "#1d1d1d"))))
        item.setData(256, severity)  # Qt.UserRole
        self.log.insertItem(0, item)
        while self.log.count() > MAX_MESSAGES:
            self.log.takeItem(self.log.count() - 1)

    def messages(self) -> list[str]:
        """Every message text, newest first (for tests and copy-paste)."""
        return [self.log.item(row).text() for row in range(self.log.count())]

    def entries(self) -> list[tuple[str, str]]:
        """Every message as its text and its detail (tooltip), newest first."""
        items = (self.log.item(row) for row in range(self.log.count()))
        return [(item.text(), item.toolTip()) for item in items]

    def detail_of(self, text: str) -> str:
        """The detail of the newest message whose text holds ``text`` ("" if none)."""
        return next((detail for said, detail in self.entries() if text in said), "")
