"""The station's parts of the command window: Show 3D view, File > Quit and the mission clock.

*Show 3D view* (View menu, and a button in the menu bar's corner) starts rviz if it is not
running, or brings it to the front; the clock beside it shows the mission time (the
replayed time during a replay). What lies outside the window (rviz, the clock's source)
comes in through :class:`StationHooks`, so this module stays free of ROS.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING

from python_qt_binding.QtCore import QTimer
from python_qt_binding.QtGui import QKeySequence
from python_qt_binding.QtWidgets import QAction, QHBoxLayout, QLabel, QToolButton, QWidget

from ..core.station_layout import MISSION, clock_text

if TYPE_CHECKING:
    from .command_widget import CommandWidget

CLOCK_MS = 500  # the clock is read twice a second, so it never skips a second
ClockReading = tuple[float | None, str]  # seconds (None: not known yet), and their label


@dataclass
class StationHooks:
    """The station outside the window.

    Attributes:
        show_3d: Start rviz or bring it to the front; returns what happened, in a sentence.
        clock: The mission clock now: seconds and their label (see :func:`clock_text`).
    """

    show_3d: Callable[[], str]
    clock: Callable[[], ClockReading]


class StationMenu:
    """Adds Show 3D view, File > Quit and the clock to ``widget``; ``quit`` closes the window."""

    def __init__(self, widget: CommandWidget, hooks: StationHooks, quit_: Callable[[], None]):
        self._widget = widget
        self.hooks = hooks
        self.show_3d = QAction("Show &3D view", widget)
        self.show_3d.setObjectName("show_3d_view")
        self.show_3d.setShortcut(QKeySequence("Ctrl+3"))
        self.show_3d.setToolTip("Open rviz (the 3D view of the site), or bring it to the front")
        self.show_3d.triggered.connect(self._on_show_3d_triggered)
        self.quit = QAction("&Quit", widget)
        self.quit.setObjectName("quit")
        self.quit.setShortcut(QKeySequence("Ctrl+Q"))  # the standard key is empty on some platforms
        self.quit.triggered.connect(lambda _=False: quit_())
        menu_bar = widget.menu_bar
        file_menu = menu_bar.actions()[0].menu()
        file_menu.addSeparator()
        file_menu.addAction(self.quit)
        menu_bar.addMenu("&View").addAction(self.show_3d)
        self.clock = QLabel(clock_text(None))
        self.clock.setObjectName("mission_clock")
        self.clock.setToolTip("Mission time: the simulation's time since it started")
        # as wide as its longest reading, so that the menu bar's corner never cuts it
        widest = self.clock.fontMetrics().horizontalAdvance(clock_text(359999, MISSION))
        self.clock.setMinimumWidth(widest + 4)
        button = QToolButton()
        button.setObjectName("show_3d_button")
        button.setDefaultAction(self.show_3d)
        corner = QWidget()
        row = QHBoxLayout(corner)
        row.setContentsMargins(4, 0, 4, 0)
        row.addWidget(self.clock)
        row.addWidget(button)
        menu_bar.setCornerWidget(corner)
        self._timer = QTimer(widget)
        self._timer.setInterval(CLOCK_MS)
        self._timer.timeout.connect(self.tick)
        self._timer.start()
        self.tick()

    def tick(self) -> None:
        """Show the clock as it reads now (the replay's while a replay is shown)."""
        replay = getattr(self._widget, "replay", None)  # made once the node is up
        seconds, label = (
            replay.clock() if replay is not None and replay.active else self.hooks.clock()
        )
        self.clock.setText(clock_text(seconds, label))

    def _on_show_3d_triggered(self) -> None:
        self._widget.messages.say(self.hooks.show_3d(), "info")
