"""The message area: standing warnings on top, then every answer and error as a sentence.

Nothing fails silently: each server answer, refusal, lost connection and local problem
lands here with its time, newest first, coloured by severity.
"""

from __future__ import annotations

import time
from collections.abc import Sequence

from python_qt_binding.QtCore import Qt, Signal
from python_qt_binding.QtGui import QBrush, QColor
from python_qt_binding.QtWidgets import (
    QFrame,
    QHBoxLayout,
    QLabel,
    QListWidget,
    QListWidgetItem,
    QPushButton,
    QScrollArea,
    QSplitter,
    QVBoxLayout,
    QWidget,
)

from .labels import never_widen

MAX_MESSAGES = 300
LOG_LINES = 3  # message lines kept in view under the warnings
MIN_FIT_WIDTH = 200  # before the first layout, fit the warnings to at least this width
WARNINGS_SHARE = 0.25  # of the window's height the warnings may take before they scroll
MIN_WARNINGS_HEIGHT = 60
PANE_FLOOR = 120  # the least a pane above keeps when the messages claim room
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
        # Many long warnings on a small screen scroll inside their box, never cut short.
        self.warnings_box = QScrollArea()
        self.warnings_box.setObjectName("warnings_box")
        self.warnings_box.setWidgetResizable(True)
        self.warnings_box.setFrameShape(QFrame.NoFrame)
        self.warnings_box.setHorizontalScrollBarPolicy(Qt.ScrollBarAlwaysOff)
        self.warnings_box.setWidget(self.warnings_label)
        self.warnings_box.hide()
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
        layout.addWidget(self.warnings_box)
        layout.addWidget(self.hold_bar)
        layout.addWidget(self.log)
        self.warnings: list[str] = []

    def show_warnings(self, warnings: Sequence[str]) -> None:
        """Replace the standing warnings (hidden when there are none)."""
        if list(warnings) == self.warnings:
            return
        self.warnings = list(warnings)
        self.warnings_label.setText("<br>".join(f"⚠ {w}" for w in warnings))
        self.warnings_box.setVisible(bool(warnings))
        self._fit()

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
        self._fit()

    def resizeEvent(self, event: object) -> None:
        """A new width wraps the warnings anew: keep room for all of them."""
        super().resizeEvent(event)
        self._fit()

    def _fit(self) -> None:
        """Give the warnings the lines they need, up to a share of the window (beyond it
        they scroll), and keep a few messages in view under them: a warning cut to its
        first line tells the operator half of it."""
        if not self.warnings_box.isHidden():
            # Fit to the width left beside a scroll bar: with it, the text wraps no more.
            bar = self.warnings_box.verticalScrollBar().sizeHint().width()
            width = max(self.warnings_box.width() - bar, MIN_FIT_WIDTH)
            wanted = self.warnings_label.heightForWidth(width) + 12  # border, padding, margins
            room = max(MIN_WARNINGS_HEIGHT, int(self.window().height() * WARNINGS_SHARE))
            height = min(wanted, room)
            if height != self.warnings_box.height():
                self.warnings_box.setFixedHeight(height)
        need = LOG_LINES * self.log.fontMetrics().lineSpacing() + 12
        if not self.warnings_box.isHidden():
            need += self.warnings_box.height()
        if not self.hold_bar.isHidden():
            need += self.hold_bar.sizeHint().height()
        if need != self.minimumHeight():
            self.setMinimumHeight(need)
        self._claim(need)

    def _claim(self, need: int) -> None:
        """Take the room ``need`` from the panes above in the splitter, the first (the
        parameters, which scroll) first: a splitter keeps its sizes when a minimum grows."""
        splitter = self.parentWidget()
        if not isinstance(splitter, QSplitter):
            return
        sizes, here = splitter.sizes(), splitter.indexOf(self)
        deficit = need - sizes[here]
        for index in range(here):
            if deficit <= 0:
                break
            pane = splitter.widget(index)
            spare = sizes[index] - max(pane.minimumSizeHint().height(), PANE_FLOOR)
            taken = max(0, min(spare, deficit))
            sizes[index] -= taken
            sizes[here] += taken
            deficit -= taken
        if sizes != splitter.sizes():
            splitter.setSizes(sizes)

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
