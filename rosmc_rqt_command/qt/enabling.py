"""Which of the window's actions are enabled: what the server would accept now.

The rules are the core's (:mod:`rosmc_server.core.rules.legality`, through
:mod:`..core.legality`); this part only applies them to the actions, the undo history and
each robot's column, and keeps each robot's result between updates so a live report
recomputes only its robot.
"""

from __future__ import annotations

from collections.abc import Iterable

from ..core.legality import RobotAction, RobotLegality, legal_actions
from ..core.mission_view import MissionView
from .actions import CommandActions
from .task_widget import TaskWidget
from .undo_history import UndoHistory

# What a window that follows a replay still offers (saving what it shows).
READ_ONLY_FILE_ITEMS = ("save_as",)


class Enabling:
    """Enables the window's actions for the selection and the robots' states."""

    def __init__(
        self,
        view: MissionView,
        actions: CommandActions,
        tasks: TaskWidget,
        history: UndoHistory,
    ) -> None:
        self._view = view
        self._actions = actions
        self._tasks = tasks
        self._history = history
        self.robots = RobotLegality()
        self.read_only = False

    def legal_for_all(self) -> set[RobotAction]:
        """Robot actions legal on at least one robot (as last worked out)."""
        return self.robots.any()

    def update(self, agents: Iterable[str] | None = None) -> None:
        """Enable what is legal now; only ``agents``' robot actions are recomputed."""
        read_only = self.read_only
        self._history.set_read_only(read_only)
        agents = None if agents is None else list(agents)
        self.robots.update(self._view, agents)
        selected = self._view.skills(self._tasks.selected_ids)
        legal = set() if read_only else legal_actions(self._view, selected)
        for kind, action in self._actions.skill.items():
            action.setEnabled(kind in legal)
        everyone = set() if read_only else self.robots.any()
        for robot_action, action in self._actions.all_robots.items():
            action.setEnabled(robot_action in everyone)
        for name, action in self._actions.file.items():
            action.setEnabled(not read_only or name in READ_ONLY_FILE_ITEMS)
        for agent in self._tasks.columns if agents is None else agents:
            column = self._tasks.columns.get(agent)
            if column is not None:
                column.set_legal(self.robots.of(agent), read_only)
