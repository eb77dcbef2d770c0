"""The science strip above the task panel: the score, the stones delivered, the regions.

Fed from ``/rosmc/sim/science`` by the ROS bridge (as a core
:class:`~rosmc_server.core.views.science.Science`); says "no score published" until the
simulator (or a real science tally) publishes one.
"""

from __future__ import annotations

from html import escape

from python_qt_binding.QtWidgets import QLabel, QWidget

from rosmc_server.core.views.science import IDENTIFIED_WORDS, Science
from rosmc_server.core.views.vocabulary import counted

from .labels import never_widen

NO_SCORE = "Science: no score published"
NO_REPLAY_SCORE = "Science (replay): no score in this recording yet"
_MARK = {"": "○", "science_rover": "◐", "collaborative": "●"}


class ScienceStrip(QLabel):  # type: ignore[misc]
    """One line (wrapped when long) with the mission's science; the regions in its tooltip."""

    def __init__(self, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.setObjectName("science")
        never_widen(self)
        self.setStyleSheet("QLabel#science { background:#eef5e9; padding:3px; }")
        self.science: Science | None = None
        self.show_science(None)

    def show_science(self, science: Science | None) -> None:
        """Show ``science`` (None: nothing published)."""
        self.science = science
        if science is None:
            self.setText(NO_SCORE)
            self.setToolTip("The simulator publishes the score on /rosmc/sim/science.")
            return
        parts = [
            f"<b>Science score {science.score:.2f}</b>",
            f"{counted(science.stones_delivered, 'stone')} delivered to the lander",
        ]
        for r in science.regions:
            parts.append(
                f"{_MARK.get(r.identified_by, '●')} {escape(r.name)} ({r.x:g}, {r.y:g}): "
                f"{escape(IDENTIFIED_WORDS.get(r.identified_by, r.identified_by))}, "
                f"{r.stones_left} left"
            )
        if not science.regions:
            parts.append("no region discovered yet")
        self.setText(" · ".join(parts))
        self.setToolTip("\n".join(science.lines()))

    def show_replay_start(self) -> None:
        """A replay begins: the live score must not pass for the recording's."""
        self.show_science(None)
        self.setText(NO_REPLAY_SCORE)

    def plain_text(self) -> str:
        """What the strip says, without markup (for tests and screen readers)."""
        return NO_SCORE if self.science is None else "\n".join(self.science.lines())
