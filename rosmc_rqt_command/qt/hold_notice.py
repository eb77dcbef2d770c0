"""The notice in a robot's column that it holds after its lost-link policy, with Resume.

A robot holding after its lost-link return starts no new work and its barrier partners
wait for it; only Resume frees it. The notice says so in words where the operator looks
(the robot's header) and puts that one action one click away. Hidden while the robot
does not hold (:mod:`..core.holding` decides).
"""

from __future__ import annotations

from python_qt_binding.QtCore import Qt, Signal
from python_qt_binding.QtWidgets import QFrame, QLabel, QPushButton, QVBoxLayout, QWidget

from ..core.holding import Hold
from .labels import never_widen

STYLE = (
    "QFrame#hold_notice { background:#fde2e1; border:1px solid #c0182b; border-radius:3px; }"
    " QLabel { color:#8a0010; }"
)


class HoldNotice(QFrame):  # type: ignore[misc]
    """ "r4 holds at its lost-link return point — its barrier partners r1, r2 wait." and a
    *Resume r4* button."""

    resume_requested = Signal()

    def __init__(self, agent: str, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.setObjectName("hold_notice")
        self.setStyleSheet(STYLE)
        self.text = never_widen(QLabel(""))
        self.text.setObjectName(f"hold_text_{agent}")
        self.resume_button = QPushButton(f"Resume {agent}")
        self.resume_button.setObjectName(f"hold_resume_{agent}")
        self.resume_button.setToolTip(f"Let {agent} go on with its work (its barrier partners too)")
        self.resume_button.clicked.connect(self._on_resume_button_clicked)
        layout = QVBoxLayout(self)  # the button under the words: fits a compact column
        layout.setContentsMargins(4, 2, 4, 2)
        layout.addWidget(self.text)
        layout.addWidget(self.resume_button, 0, Qt.AlignLeft)
        self.hold: Hold | None = None
        self.setVisible(False)

    def show_hold(self, hold: Hold | None) -> None:
        """Say ``hold`` (None: hide the notice)."""
        if hold == self.hold:
            return
        self.hold = hold
        self.text.setText(hold.sentence() if hold is not None else "")
        self.setVisible(hold is not None)

    def _on_resume_button_clicked(self) -> None:
        self.resume_requested.emit()
