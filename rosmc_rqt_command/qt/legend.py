"""A key of the row colours, under the task panel: what each colour means.

Built from :mod:`.presentation`, so the key always matches the rows. One label that wraps
onto a second line in a narrow window (a row of chips would hold the window wide).
"""

from __future__ import annotations

from html import escape

from python_qt_binding.QtWidgets import QLabel, QWidget

from rosmc_server.core import SkillStatus

from ..core import presentation
from .labels import never_widen

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


class StatusLegend(QLabel):  # type: ignore[misc]
    """Colour chips with the status words, wrapped to the width given."""

    def __init__(self, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.setObjectName("legend")
        never_widen(self)
        self.setContentsMargins(4, 0, 4, 2)
        self.chips: dict[str, str] = {}  # words -> background colour
        chips = []
        for words, background, text in ENTRIES:
            # Non-breaking spaces: a line breaks between chips, never inside one.
            shown = escape(words).replace(" ", "&nbsp;")
            chips.append(
                f"<span style='background:{background}; color:{text};'>&nbsp;{shown}&nbsp;</span>"
            )
            self.chips[words] = background
        self.setText("Colours: " + " &nbsp;".join(chips))
