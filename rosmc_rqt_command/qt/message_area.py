"""The message area: standing warnings on top, then every answer and error as a sentence.

Nothing fails silently: each server answer, refusal, lost connection and local problem
lands here with its time, newest first, coloured by severity.
"""

from __future__ import annotations

import time
from collections.abc import Sequence

from python_qt_binding.QtGui import QBrush, QColor
from python_qt_binding.QtWidgets import QLabel, QListWidget, QListWidgetItem, QVBoxLayout, QWidget

from .labels import never_widen

MAX_MESSAGES = 300
SEVERITY_COLOURS = {"info": "#1d1d1d", "ok": "#11632b", "warning": "#8a5a00", "error": "#b00020"}


class MessageArea(QWidget):  # type: ignore[misc]
    """Warnings and the log of messages."""

    def __init__(self, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.warnings_label = QLabel("")
        self.warnings_label.setObjectName("warnings")
        never_widen(self.warnings_label)  # a long warning wraps, the window keeps its width
        self.warnings_label.setStyleSheet(
            "QLabel { background:#fff3c4; border:1px solid #e0b000; padding:4px; }"
        )
        self.warnings_label.hide()
        self.log = QListWidget()
        self.log.setObjectName("messages")
        self.log.setWordWrap(True)
        self.log.setAlternatingRowColors(True)
        layout = QVBoxLayout(self)
        layout.setContentsMargins(0, 0, 0, 0)
        layout.addWidget(self.warnings_label)
        layout.addWidget(self.log)
        self.warnings: list[str] = []

    def show_warnings(self, warnings: Sequence[str]) -> None:
        """Replace the standing warnings (hidden when there are none)."""
        if list(warnings) == self.warnings:
            return
        self.warnings = list(warnings)
        self.warnings_label.setText("<br>".join(f"⚠ {w}" for w in warnings))
        self.warnings_label.setVisible(bool(warnings))

    def say(self, text: str, severity: str = "info") -> None:
        """Add one message (``severity``: info, ok, warning or error)."""
        item = QListWidgetItem(f"{time.strftime('%H:%M:%S')}  {text}")
        item.setForeground(QBrush(QColor(SEVERITY_COLOURS.get(severity, "#1d1d1d"))))
        item.setData(256, severity)  # Qt.UserRole
        self.log.insertItem(0, item)
        while self.log.count() > MAX_MESSAGES:
            self.log.takeItem(self.log.count() - 1)

    def messages(self) -> list[str]:
        """Every message text, newest first (for tests and copy-paste)."""
        return [self.log.item(row).text() for row in range(self.log.count())]
