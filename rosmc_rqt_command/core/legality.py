"""Which operator actions make sense for the current selection (so buttons can be enabled).

The mission server is the judge: it refuses anything illegal with a sentence. These
read-only checks only keep the operator from pressing buttons that cannot work, using
the skill's own properties (``is_editable``, ``status``, ``resolution``) and the sections
the mirror computed. No Qt here.
"""

from __future__ import annotations

import enum
from collections.abc import Iterable, Sequence

from rosmc_server.core import Resolution, SkillInstance, SkillStatus, Transfer

from .mission_view import MissionView

# What an executor reports (AgentStatus.executor_state) while it is allowed to execute.
_STARTED_STATES = frozenset({"idle", "running", "waiting", "holding", "contingency"})


class Action(enum.Enum):
    """Everything the control panel, context menus and shortcuts can do to skills."""

    DELETE = "delete"
    MOVE_UP = "move_up"
    MOVE_DOWN = "move_down"
    SYNC = "synchronize"
    UNSYNC = "unsynchronize"
    RETRY = "retry"
    SKIP = "skip"
    BARRIER = "barrier"
    DELETE_BARRIER = "delete_barrier"


class RobotAction(enum.Enum):
    """What can be done to one robot (or to all of them)."""

    SYNC_ALL = "synchronize_all"
    UNSYNC_ALL = "unsynchronize_all"
    START = "start"
    PAUSE = "pause"
    RESUME = "resume"
    STOP = "stop"


def selection_agent(selected: Sequence[SkillInstance]) -> str | None:
    """The one robot every selected skill belongs to (None if none or several)."""
    agents = {skill.agent for skill in selected}
    return agents.pop() if len(agents) == 1 else None


def legal_actions(view: MissionView, selected: Sequence[SkillInstance]) -> set[Action]:
    """The skill actions that can work on ``selected`` now."""
    legal: set[Action] = set()
    if not selected:
        return legal
    agent = selection_agent(selected)
    if all(skill.is_editable for skill in selected):
        legal.update((Action.DELETE, Action.SYNC))  # several robots: one team send
        if agent is not None:
            editable = view.view(agent).editable
            ids = [skill.id for skill in editable]
            picked = sorted(ids.index(s.id) for s in selected if s.id in ids)
            if picked and picked[0] > 0:
                legal.add(Action.MOVE_UP)
            if picked and picked[-1] < len(ids) - 1:
                legal.add(Action.MOVE_DOWN)
    unsyncable = all(
        s.status is SkillStatus.IDLE_SYNCHRONIZED and s.transfer is Transfer.NONE for s in selected
    )
    if agent is not None and unsyncable:
        legal.add(Action.UNSYNC)
    if len(selected) == 1:
        skill = selected[0]
        if skill.status is SkillStatus.FAILURE and skill.resolution is Resolution.NONE:
            legal.update((Action.RETRY, Action.SKIP))
    agents = {skill.agent for skill in selected}
    free = all(not s.status.has_started and view.barrier_of(s.id) is None for s in selected)
    if len(selected) >= 2 and len(agents) == len(selected) and free:
        legal.add(Action.BARRIER)
    barriers = [b for s in selected if (b := view.barrier_of(s.id)) is not None]
    if barriers and all(
        not member.status.has_started
        for barrier in barriers
        for member in view.skills(barrier.skill_ids)
    ):
        legal.add(Action.DELETE_BARRIER)
    return legal


def legal_robot_actions(view: MissionView, agent: str) -> set[RobotAction]:
    """The robot actions that can work on ``agent`` now."""
    task = view.view(agent)
    legal: set[RobotAction] = set()
    if task.editable:
        legal.add(RobotAction.SYNC_ALL)
    synced = task.synced
    if any(
        s.status is SkillStatus.IDLE_SYNCHRONIZED and s.transfer is Transfer.NONE for s in synced
    ):
        legal.add(RobotAction.UNSYNC_ALL)
    status = view.statuses.get(agent)
    state = status.executor_state if status is not None else ""
    active = [s for s in synced if s.status.is_active]
    pending = [s for s in synced if not s.status.is_final]
    paused = state == "paused" or any(s.status is SkillStatus.PAUSED for s in active)
    started = state in _STARTED_STATES
    if pending and not started and not paused:
        legal.add(RobotAction.START)
    moving = any(s.status in (SkillStatus.RUNNING, SkillStatus.SYNCWAITING) for s in active)
    if (started or moving) and not paused:
        legal.add(RobotAction.PAUSE)
    if paused:
        legal.add(RobotAction.RESUME)
    if active or started or paused:
        legal.add(RobotAction.STOP)
    return legal


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
