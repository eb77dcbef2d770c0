"""The bar above the task panel for large teams: filter robots by name and status, compact mode.

With 20 robots the task panel holds more columns than a screen: it scrolls sideways, and
this bar narrows it. A text field matches robot names, the *Robots* list ticks robots on
and off (it stays open while the operator ticks), the status buttons keep only robots
with a failure, something waiting or no contact, and *Compact* makes every column
narrower. Which robots pass is decided by :mod:`.team_filter` (no Qt there).
"""

from __future__ import annotations

from python_qt_binding.QtCore import Qt
from python_qt_binding.QtWidgets import (
    QAction,
    QButtonGroup,
    QLabel,
    QLineEdit,
    QMenu,
    QToolButton,
    QWidget,
)

from rosmc_server.core.views.vocabulary import counted

from ..core.mission_view import MissionView
from ..core.team_filter import StatusFilter, TeamFilter, visible_agents
from .flow_layout import FlowLayout
from .labels import never_widen
from .task_widget import TaskWidget


class StayOpenMenu(QMenu):  # type: ignore[misc]
    """A menu whose checkable entries toggle without closing it (tick several robots)."""

    def mouseReleaseEvent(self, event: object) -> None:
        """Toggle a checkable entry in place; other entries act as usual."""
        action = self.actionAt(event.pos())  # type: ignore[attr-defined]
        if action is not None and action.isCheckable() and action.isEnabled():
            action.trigger()
            return
        super().mouseReleaseEvent(event)


class TeamBar(QWidget):  # type: ignore[misc]
    """Filter and compact controls for the task panel's robot columns."""

    def __init__(self, tasks: TaskWidget, view: MissionView, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.setObjectName("team_bar")
        self._tasks = tasks
        self._view = view
        self.chosen = TeamFilter()
        self._agents: list[str] = []
        self.text = QLineEdit(self)
        self.text.setObjectName("team_filter_text")
        self.text.setPlaceholderText("Filter robots by name…")
        self.text.setClearButtonEnabled(True)
        self.text.setToolTip("Names or parts of names, separated by commas: drone, rover_3")
        self.text.setMaximumWidth(220)
        self.text.setMinimumWidth(90)
        # Not the window's first focus: the task panel's shortcuts (Delete, arrows) stay live.
        self.text.setFocusPolicy(Qt.ClickFocus)
        self.text.textChanged.connect(self._on_text_text_changed)
        self.robot_menu = StayOpenMenu(self)
        self.robot_menu.triggered.connect(self._on_robot_menu_triggered)
        self.robots_button = QToolButton(self)
        self.robots_button.setObjectName("team_robots")
        self.robots_button.setText("Robots ▾")
        self.robots_button.setToolTip("Tick the robots whose columns to show")
        self.robots_button.clicked.connect(self._on_robots_button_clicked)
        self.status_buttons: dict[StatusFilter, QToolButton] = {}
        self._status_group = QButtonGroup(self)
        for status in StatusFilter:
            button = QToolButton(self)
            button.setObjectName(f"team_status_{status.value}")
            button.setText(status.label)
            button.setToolTip(status.tip)
            button.setCheckable(True)
            button.setChecked(status is StatusFilter.ALL)
            button.clicked.connect(lambda _=False, s=status: self._on_status_clicked(s))
            self._status_group.addButton(button)
            self.status_buttons[status] = button
        self.compact = QToolButton(self)
        self.compact.setObjectName("team_compact")
        self.compact.setText("Compact")
        self.compact.setCheckable(True)
        self.compact.setToolTip("Narrow columns without step numbers and parameters")
        self.compact.toggled.connect(self._on_compact_toggled)
        self.count = QLabel(self)
        self.count.setObjectName("team_count")
        never_widen(self.count, wrap=False)
        self.count.setAlignment(Qt.AlignRight | Qt.AlignVCenter)
        # The controls wrap onto a second row in a narrow window (half a screen wide).
        layout = FlowLayout(self)
        layout.setContentsMargins(2, 0, 2, 0)
        layout.addWidget(self.text)
        layout.addWidget(self.robots_button)
        layout.addWidget(QLabel("Show:", self))
        for button in self.status_buttons.values():
            layout.addWidget(button)
        layout.addWidget(self.compact)
        layout.addWidget(self.count)

    def refresh(self) -> None:
        """Apply the filter and compact mode to the columns (after updates and reports)."""
        agents = list(self._tasks.columns)
        if agents != self._agents:
            self._agents = agents
            self._fill_robot_menu()
        compact = self.compact.isChecked()
        shown = set(visible_agents(self._view, agents, self.chosen))
        for agent, column in self._tasks.columns.items():
            column.set_compact(compact)
            column.setVisible(agent in shown)
        self.count.setText(f"{len(shown)} of {counted(len(agents), 'robot')} shown")
        self.count.setStyleSheet("QLabel { color:#8a0010; }" if self.chosen.active else "")

    def visible(self) -> list[str]:
        """The robots whose columns are shown now, in order."""
        return [a for a, c in self._tasks.columns.items() if not c.isHidden()]

    def _fill_robot_menu(self) -> None:
        self.robot_menu.clear()
        everyone = self.robot_menu.addAction("Show all robots")
        everyone.setObjectName("team_robots_all")
        self.robot_menu.addSeparator()
        for agent in self._agents:
            action = self.robot_menu.addAction(agent)
            action.setObjectName(f"team_robot_{agent}")
            action.setCheckable(True)
            action.setChecked(agent not in self.chosen.hidden)

    def _on_robots_button_clicked(self) -> None:
        self.robot_menu.popup(
            self.robots_button.mapToGlobal(self.robots_button.rect().bottomLeft())
        )

    def _on_robot_menu_triggered(self, action: QAction) -> None:
        if action.isCheckable():
            self.chosen = self.chosen.with_shown(action.text(), action.isChecked())
        else:  # "Show all robots"
            self.chosen = TeamFilter(self.chosen.text, frozenset(), self.chosen.status)
            for entry in self.robot_menu.actions():
                if entry.isCheckable():
                    entry.setChecked(True)
        self.refresh()

    def _on_text_text_changed(self, text: str) -> None:
        self.chosen = self.chosen.with_text(text)
        self.refresh()

    def _on_status_clicked(self, status: StatusFilter) -> None:
        self.chosen = self.chosen.with_status(status)
        self.refresh()

    def _on_compact_toggled(self, _checked: bool) -> None:
        self.refresh()
