"""Every command of the GUI as a QAction with its text, shortcut and tooltip.

Buttons, context menus and the menu bar share these actions, so one ``setEnabled`` keeps
them all honest. Shortcuts work anywhere inside the command widget (not elsewhere in
rqt).
"""

from __future__ import annotations

from python_qt_binding.QtCore import QObject, Qt
from python_qt_binding.QtGui import QKeySequence
from python_qt_binding.QtWidgets import QAction, QWidget

from ..core.legality import Action, RobotAction

# (text, shortcuts, tooltip) of each skill action ("A|B": either key sequence).
SKILL_ACTIONS: dict[Action, tuple[str, str, str]] = {
    Action.DELETE: ("Delete", "Delete", "Delete the selected planned skills"),
    Action.MOVE_UP: ("Move up", "Alt+Up|Ctrl+Up", "Move the selected skills one earlier"),
    Action.MOVE_DOWN: ("Move down", "Alt+Down|Ctrl+Down", "Move the selected skills one later"),
    Action.SYNC: (
        "Send to robot",
        "Ctrl+Return",
        "Send the planned skills up to the selected one to the robot",
    ),
    Action.UNSYNC: (
        "Take back",
        "Ctrl+Backspace",
        "Take the selected skill and the ones after it back from the robot into the plan",
    ),
    Action.RETRY: ("Retry", "Ctrl+R", "Run the failed skill again"),
    Action.SKIP: ("Skip", "Ctrl+K", "Leave the failed skill and go on with the next one"),
    Action.BARRIER: (
        "Start together",
        "Ctrl+B",
        "Barrier: the selected skills (one per robot) start at the same time",
    ),
    Action.DELETE_BARRIER: (
        "Remove barrier",
        "Ctrl+Shift+B",
        "The selected skills no longer wait for each other",
    ),
}
# (text, shortcut, tooltip) of each action on every robot at once.
ALL_ROBOT_ACTIONS: dict[RobotAction, tuple[str, str, str]] = {
    RobotAction.SYNC_ALL: (
        "Send all robots",
        "F4",
        "Send every robot its whole plan in one step (one question, all or nothing)",
    ),
    RobotAction.START: ("Start all", "F6", "Start every robot"),
    RobotAction.PAUSE: ("Pause all", "F7", "Pause every robot"),
    RobotAction.RESUME: ("Resume all", "F8", "Resume every robot"),
    RobotAction.STOP: ("Stop all", "F9", "Stop every robot"),
}
FILE_ACTIONS: dict[str, tuple[str, str, str]] = {
    "new": ("&New mission", "Ctrl+N", "Start an empty mission"),
    "open": ("&Open file…", "Ctrl+O", "Load a mission file from this computer"),
    "open_server": (
        "Open file on &server…",
        "Ctrl+Shift+O",
        "Load a mission file from the mission server's computer",
    ),
    "save": ("&Save", "Ctrl+S", "Save the mission where it was last saved"),
    "save_as": ("Save &as…", "Ctrl+Shift+S", "Save the mission to a file on this computer"),
    "save_server": (
        "Save on s&erver as…",
        "Ctrl+Alt+S",
        "Save the mission to a file on the mission server's computer",
    ),
}


class CommandActions(QObject):  # type: ignore[misc]
    """The actions of one command widget (shortcuts active within ``owner``)."""

    def __init__(self, owner: QWidget) -> None:
        super().__init__(owner)
        self.skill: dict[Action, QAction] = {}
        self.all_robots: dict[RobotAction, QAction] = {}
        self.file: dict[str, QAction] = {}
        for action, (text, keys, tip) in SKILL_ACTIONS.items():
            self.skill[action] = self.make(owner, text, keys, tip, action.value)
        for robot_action, (text, keys, tip) in ALL_ROBOT_ACTIONS.items():
            self.all_robots[robot_action] = self.make(
                owner, text, keys, tip, f"{robot_action.value}_all"
            )
        for name, (text, keys, tip) in FILE_ACTIONS.items():
            self.file[name] = self.make(owner, text, keys, tip, name)
        self.refresh = self.make(owner, "Refresh", "F5", "Fetch the mission again", "refresh")
        self.clear_selection = self.make(owner, "Select nothing", "Escape", "", "clear")

    @staticmethod
    def make(owner: QWidget, text: str, keys: str, tip: str, name: str) -> QAction:
        """A QAction of ``owner`` with its shortcuts ("A|B": either), tooltip and name."""
        action = QAction(text, owner)
        action.setObjectName(f"action_{name}")
        if keys:
            # "A|B": two key sequences for one action (the first is shown in menus).
            action.setShortcuts([QKeySequence(k) for k in keys.split("|")])
            action.setShortcutContext(Qt.WidgetWithChildrenShortcut)
            words = keys.replace("|", " or ")
            tip = f"{tip} ({words})" if tip else words
        action.setToolTip(tip)
        action.setStatusTip(tip)
        owner.addAction(action)
        return action
