"""The operator's hands on the command GUI's large-team bar (offscreen Qt, real widget).

Shared by the unit test (a staged mission) and the integration test (a real server) of
the 20-robot command GUI: scroll with the scroll bar's arrow, click the bar's buttons,
tick robots in the robot list, and tell which columns are wholly on screen.
"""

from __future__ import annotations

from python_qt_binding.QtCore import QPoint, QRect, Qt
from python_qt_binding.QtTest import QTest
from python_qt_binding.QtWidgets import QApplication

from rosmc_rqt_command.qt.agent_column import AgentColumn
from rosmc_rqt_command.qt.command_widget import CommandWidget
from rosmc_rqt_command.qt.team_bar import TeamBar
from tests import conftest


def settle(widget: CommandWidget) -> None:
    """Let Qt lay the columns out (and show the robots' reports)."""
    timer = widget.repaints.status_timer
    conftest.wait_until(lambda: not timer.isActive(), 10, "reports shown", pause=conftest.qt_pause)
    for _ in range(3):
        QApplication.processEvents()


def on_screen(widget: CommandWidget) -> list[str]:
    """Robots whose whole column is inside the task panel's viewport now."""
    panel = widget.tasks
    viewport = panel.viewport().rect()
    shown = []
    for agent, column in panel.columns.items():
        if column.isVisible():
            top_left = column.mapTo(panel.viewport(), QPoint(0, 0))
            if viewport.contains(QRect(top_left, column.size())):
                shown.append(agent)
    return shown


def step_right(widget: CommandWidget) -> None:
    """Click the scroll bar's right arrow, as with the mouse."""
    bar = widget.tasks.horizontalScrollBar()
    arrow = bar.height()  # the arrow buttons are square
    arrow_centre = QPoint(bar.width() - arrow // 2, arrow // 2)
    QTest.mouseClick(bar, Qt.LeftButton, Qt.NoModifier, arrow_centre)
    QApplication.processEvents()


def team(widget: CommandWidget) -> TeamBar:
    """The large-team bar."""
    bar: TeamBar = widget.team
    return bar


def click(widget: CommandWidget, name: str) -> None:
    """Click the widget named ``name`` and let the task panel settle."""
    target = widget.findChild(object, name)
    assert target is not None, name
    QTest.mouseClick(target, Qt.LeftButton)
    settle(widget)


def tick(widget: CommandWidget, agent: str) -> None:
    """Open the robot list with the mouse and click ``agent``'s entry."""
    click(widget, "team_robots")
    menu = team(widget).robot_menu
    conftest.wait_until(menu.isVisible, 5, "the robot list open", pause=conftest.qt_pause)
    action = next(a for a in menu.actions() if a.text() == agent)
    QTest.mouseClick(menu, Qt.LeftButton, Qt.NoModifier, menu.actionGeometry(action).center())
    # A robot's entry toggles and the list stays open; "Show all robots" closes it.
    assert menu.isVisible() is action.isCheckable()
    menu.hide()
    settle(widget)


def columns(widget: CommandWidget) -> dict[str, AgentColumn]:
    """The robots' columns, in order."""
    cols: dict[str, AgentColumn] = widget.tasks.columns
    return cols
