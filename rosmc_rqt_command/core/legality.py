"""Which operator actions make sense for the current selection (so buttons can be enabled).

The rules live in :mod:`rosmc_server.core.rules.legality`, where the server's own checks use
them: a button is enabled exactly when the server would accept its request against the
mission shown. This module applies them to the GUI's :class:`~.mission_view.MissionView`
and keeps each robot's result between updates. No Qt here.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence

from rosmc_server.core import SkillInstance
from rosmc_server.core.model.control import ExecutorState
from rosmc_server.core.rules.legality import RobotAction, legal_skill_actions, selection_agent
from rosmc_server.core.rules.legality import SkillAction as Action
from rosmc_server.core.rules.legality import legal_robot_actions as robot_rules

from .mission_view import MissionView

__all__ = [
    "Action",
    "RobotAction",
    "RobotLegality",
    "legal_actions",
    "legal_for_all",
    "legal_robot_actions",
    "selection_agent",
]


def legal_actions(view: MissionView, selected: Sequence[SkillInstance]) -> set[Action]:
    """The skill actions the server would accept for ``selected`` now."""
    return legal_skill_actions(view, selected)


def legal_robot_actions(view: MissionView, agent: str) -> set[RobotAction]:
    """The robot actions that can work on ``agent`` now."""
    status = view.statuses.get(agent)
    state = status.executor if status is not None else ExecutorState.UNKNOWN
    return robot_rules(view.view(agent), state)


def legal_for_all(view: MissionView) -> set[RobotAction]:
    """Robot actions that can work on at least one robot."""
    legal: set[RobotAction] = set()
    for agent in view.agents:
        legal |= legal_robot_actions(view, agent)
    return legal


class RobotLegality:
    """Each robot's legal actions, recomputed only for robots an update touched.

    Enabling the all-robot buttons needs every robot's actions; walking every robot's
    task on every live update would cost O(mission) each time.
    """

    def __init__(self) -> None:
        self._by_agent: dict[str, frozenset[RobotAction]] = {}

    def update(self, view: MissionView, agents: Iterable[str] | None = None) -> None:
        """Recompute ``agents`` (None: every robot, e.g. after a new mission)."""
        if agents is None:
            self._by_agent = {}
            agents = view.agents
        for agent in agents:
            self._by_agent[agent] = frozenset(legal_robot_actions(view, agent))

    def of(self, agent: str) -> set[RobotAction]:
        """``agent``'s legal actions as last computed."""
        return set(self._by_agent.get(agent, ()))

    def any(self) -> set[RobotAction]:
        """Actions legal on at least one robot."""
        legal: set[RobotAction] = set()
        for actions in self._by_agent.values():
            legal |= actions
        return legal
