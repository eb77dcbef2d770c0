"""A one-line key of the row colours, under the task panel: what each colour means.

Built from :mod:`.presentation`, so the key always matches the rows.
"""

from __future__ import annotations

from python_qt_binding.QtWidgets import QHBoxLayout, QLabel, QWidget

from rosmc_server.core import SkillStatus

from ..core import presentation

# (words, background, text colour) in the order a skill lives through them.
ENTRIES = (
    ("planned", presentation.STATUS_COLOURS[SkillStatus.IDLE], presentation.TEXT_COLOUR),
    ("uploading / removing", presentation.TRANSFER_COLOUR, presentation.TEXT_COLOUR),
    *(
        (presentation.STATUS_WORDS[status], presentation.STATUS_COLOURS[status], text)
        for status, text in (
            (SkillStatus.IDLE_SYNCHRONIZED, presentation.TEXT_COLOUR),
            (SkillStatus.SYNCWAITING, presentation.TEXT_COLOUR),
            (SkillStatus.RUNNING, presentation.TEXT_COLOUR),
            (SkillStatus.PAUSED, presentation.TEXT_COLOUR),
            (SkillStatus.SUCCESS, presentation.DONE_TEXT_COLOUR),
            (SkillStatus.FAILURE, presentation.ALARM_TEXT_COLOUR),
        )
    ),
    (
        "failed, retried or skipped",
        presentation.SETTLED_FAILURE_COLOUR,
        presentation.DONE_TEXT_COLOUR,
    ),
)


class StatusLegend(QWidget):  # type: ignore[misc]
    """Colour chips with the status words, in one row."""

    def __init__(self, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.setObjectName("legend")
        layout = QHBoxLayout(self)
        layout.setContentsMargins(4, 0, 4, 2)
        layout.setSpacing(4)
        layout.addWidget(QLabel("Colours:"))
        self.chips: dict[str, QLabel] = {}
        for words, background, text in ENTRIES:
            chip = QLabel(words)
            chip.setStyleSheet(
                f"QLabel {{ background:{background}; color:{text}; border:1px solid #9a9a9a;"
                " border-radius:3px; padding:1px 6px; }"
            )
            layout.addWidget(chip)
            self.chips[words] = chip
        layout.addStretch(1)
