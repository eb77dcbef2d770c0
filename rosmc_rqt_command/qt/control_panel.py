"""The control panel: buttons for the selected skills and for every robot at once.

Each button shows one shared :class:`~.actions.CommandActions` action, so it is enabled
exactly when its action is (see :mod:`.legality`); per-robot buttons live in each
robot's column.
"""

from __future__ import annotations

from python_qt_binding.QtCore import Qt
from python_qt_binding.QtWidgets import (
    QGridLayout,
    QGroupBox,
    QLabel,
    QSizePolicy,
    QToolButton,
    QVBoxLayout,
    QWidget,
)

from ..core.legality import Action, RobotAction
from .actions import CommandActions

# Two to a row, each beside its opposite, so the panel stays narrow (the task panel gets
# the width) and no button is ever cut.
SKILL_ROWS = (
    (Action.SYNC, Action.UNSYNC),
    (Action.MOVE_UP, Action.MOVE_DOWN),
    (Action.BARRIER, Action.DELETE_BARRIER),
    (Action.RETRY, Action.SKIP),
    (Action.DELETE,),
)
ROBOT_ROW = (RobotAction.START, RobotAction.PAUSE, RobotAction.RESUME, RobotAction.STOP)


class ControlPanel(QGroupBox):  # type: ignore[misc]
    """Buttons of the skill actions and of the all-robot actions."""

    def __init__(self, actions: CommandActions, parent: QWidget | None = None) -> None:
        super().__init__("Control", parent)
        self.buttons: dict[str, QToolButton] = {}
        layout = QVBoxLayout(self)
        layout.addWidget(QLabel("Selected skills:"))
        grid = QGridLayout()
        for row, kinds in enumerate(SKILL_ROWS):
            for column, kind in enumerate(kinds):
                grid.addWidget(self._button(actions.skill[kind], kind.value), row, column)
        layout.addLayout(grid)
        layout.addWidget(QLabel("All robots:"))
        send = actions.all_robots[RobotAction.SYNC_ALL]
        layout.addWidget(self._button(send, "send_all"))
        robots = QGridLayout()
        for position, robot_action in enumerate(ROBOT_ROW):
            action = actions.all_robots[robot_action]
            row, column = divmod(position, 2)  # two to a row: the panel stays narrow
            robots.addWidget(self._button(action, f"{robot_action.value}_all"), row, column)
        layout.addLayout(robots)

    def _button(self, action: object, name: str) -> QToolButton:
        button = QToolButton(self)
        button.setDefaultAction(action)
        button.setObjectName(f"button_{name}")
        button.setToolButtonStyle(Qt.ToolButtonTextOnly)
        button.setSizePolicy(QSizePolicy.Expanding, QSizePolicy.Fixed)
        self.buttons[name] = button
        return button
