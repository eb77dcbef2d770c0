"""What an operator may do now: one function per rule, for the server and both GUIs.

The server's checks (:mod:`.editing`, :mod:`.execution`, :mod:`.barriers`) call the
``*_refusal`` functions here and raise their sentence; the GUIs enable a button exactly
when the same function finds nothing to refuse. :func:`legal_skill_actions` and
:func:`legal_robot_actions` read the mission through a :class:`Picture`: the server's
:class:`~.state.MissionState` (through :class:`StatePicture`) or a GUI's own copy.
"""

from __future__ import annotations

import enum
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from typing import Protocol

from ..model.control import ExecutorState
from ..model.model import Barrier, Resolution, SkillInstance, SkillStatus, Transfer
from ..model.state import MissionState
from .deadlock import find_deadlock

S = SkillStatus


class SkillAction(enum.Enum):
    """What can be done to selected skills."""

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


@dataclass(frozen=True)
class TaskView:
    """One robot's task at one revision, split as the mission state splits it.

    ``skills[:synced_end]`` is the synchronized section, ``skills[synced_end:]`` the
    blueprint, of which ``skills[synced_end:editable_start]`` is being uploaded.
    ``uploading`` / ``removing``: an upload / an unsynchronize awaits the robot's answer.
    """

    agent: str
    skills: Sequence[SkillInstance] = ()
    synced_end: int = 0
    editable_start: int = 0
    uploading: bool = False
    removing: bool = False

    @property
    def synced(self) -> tuple[SkillInstance, ...]:
        """The synchronized section (on the robot, or being removed from it)."""
        return tuple(self.skills[: self.synced_end])

    @property
    def blueprint(self) -> tuple[SkillInstance, ...]:
        """The blueprint: skills not on the robot (the first may be uploading)."""
        return tuple(self.skills[self.synced_end :])

    @property
    def editable(self) -> tuple[SkillInstance, ...]:
        """The part of the blueprint that can be edited and reordered."""
        return tuple(self.skills[self.editable_start :])

    @classmethod
    def of(cls, state: MissionState, agent: str) -> TaskView:
        """``agent``'s task in ``state``, as an immutable copy (to hand to another thread)."""
        live = cls.live(state, agent)
        return cls(agent, tuple(live.skills), *_counts(live))

    @classmethod
    def live(cls, state: MissionState, agent: str) -> TaskView:
        """``agent``'s task over the state's own list, for a check that ends before the
        state changes (nothing is copied: the server's checks cost the change)."""
        sections = state.sections(agent)
        return cls(
            agent,
            state.task(agent),
            sections.synced_end,
            sections.editable_start,
            bool(state.pending(agent, Transfer.UPLOADING)),
            bool(state.pending(agent, Transfer.REMOVING)),
        )


def _counts(view: TaskView) -> tuple[int, int, bool, bool]:
    return view.synced_end, view.editable_start, view.uploading, view.removing


class Picture(Protocol):
    """What the rules read of a mission."""

    @property
    def agents(self) -> Iterable[str]:
        """Every robot."""

    @property
    def barriers(self) -> Sequence[Barrier]:
        """Every barrier."""

    def view(self, agent: str) -> TaskView:
        """``agent``'s task."""

    def barrier_of(self, skill_id: str) -> Barrier | None:
        """The barrier a skill is in, if any."""

    def skills(self, skill_ids: Sequence[str]) -> list[SkillInstance]:
        """The skills with these ids that exist."""


class StatePicture:
    """A :class:`Picture` of the server's mission state."""

    def __init__(self, state: MissionState) -> None:
        self._state = state

    @property
    def agents(self) -> Iterable[str]:
        """Every robot."""
        return self._state.agents

    @property
    def barriers(self) -> Sequence[Barrier]:
        """Every barrier."""
        return self._state.barriers

    def view(self, agent: str) -> TaskView:
        """``agent``'s task."""
        return TaskView.of(self._state, agent)

    def barrier_of(self, skill_id: str) -> Barrier | None:
        """The barrier a skill is in, if any."""
        return self._state.barrier_of(skill_id)

    def skills(self, skill_ids: Sequence[str]) -> list[SkillInstance]:
        """The skills with these ids that exist."""
        return [self._state.skill(i) for i in skill_ids if self._state.has_skill(i)]


# -- the rules, as sentences (None: nothing to refuse) -----------------------------------------
def failure_refusal(skill: SkillInstance, verb: str) -> str | None:
    """Why ``skill`` cannot be retried or skipped (``verb``), if it cannot."""
    if skill.status is not S.FAILURE:
        return f"skill '{skill.id}' is {skill.status.name}; only a FAILURE can be {verb}"
    if skill.resolution is not Resolution.NONE:
        return f"failed skill '{skill.id}' was already {skill.resolution.name.lower()}"
    return None


def member_refusal(skill: SkillInstance, action: str) -> str | None:
    """Why ``skill`` cannot join or leave a barrier (``action``) now, if it cannot."""
    if skill.status not in (S.IDLE, S.IDLE_SYNCHRONIZED):
        return f"skill '{skill.id}' is {skill.status.name} and can no longer {action}"
    if skill.transfer is not Transfer.NONE:
        word = "uploaded" if skill.transfer is Transfer.UPLOADING else "removed from the robot"
        return f"skill '{skill.id}' is being {word}; it can {action} once the robot has answered"
    return None


def staying_refusal(staying: Iterable[SkillInstance]) -> str | None:
    """Why a barrier cannot lose members whose partners ``staying`` stay in it, if it cannot
    (the robots hold the barrier too: once a member started, or awaits a transfer, it is fixed).
    """
    for skill in staying:
        refusal = member_refusal(skill, "have its barrier changed")
        if refusal is not None:
            return refusal
    return None


def unsync_start(task: TaskView) -> int:
    """The first synchronized index an unsynchronize may pull (after the last started)."""
    start = task.synced_end
    while start > 0 and task.skills[start - 1].status is S.IDLE_SYNCHRONIZED:
        start -= 1
    return start


def take_back_refusal(task: TaskView, index: int | None) -> str | None:
    """Why ``task``'s skills from ``index`` (None: all it may) cannot be taken back now.

    The one rule of *Take back* (the server's ``unsynchronize``, ``rosmc unsync`` and both
    GUIs). While an upload awaits the robot's answer (the robot may be out of contact for
    minutes), taking back cancels that upload: from ``index`` if it is one of the skills
    being uploaded, all of it for None. The operator can always take back what the robot
    has not confirmed; what it has confirmed comes back once it has answered. Otherwise the
    robot is asked to give back its not-started skills (:func:`unsync_refusal`).
    """
    if task.uploading:
        if index is None or task.synced_end <= index < task.editable_start:
            return None
        return (
            f"an upload to {task.agent} awaits the robot's answer; take back the upload "
            "first, or the skills on the robot once it has answered"
        )
    return unsync_refusal(task, index)


def unsync_refusal(task: TaskView, index: int | None) -> str | None:
    """Why ``task``'s synced skills from ``index`` (None: all it may) cannot be pulled back
    from the robot (no upload pending: see :func:`take_back_refusal`)."""
    agent = task.agent
    if task.removing:
        return f"an unsynchronize on {agent} already awaits the robot's answer"
    start = unsync_start(task)
    if index is not None and index < start:
        skill_id = task.skills[index].id
        return (
            f"skill '{skill_id}' or a later one has started; only skills after the last "
            "started one can be unsynchronized"
        )
    if start >= task.synced_end:
        return f"{agent} has no synchronized skills that have not started"
    return None


def sync_refusal(task: TaskView) -> str | None:
    """Why ``task``'s editable blueprint cannot be uploaded now, if it cannot."""
    if task.removing:
        return f"an unsynchronize on {task.agent} awaits the robot's answer; synchronize after it"
    if task.editable_start >= len(task.skills):
        return f"{task.agent} has no blueprint skills to synchronize"
    return None


# -- what the GUIs enable ---------------------------------------------------------------------
def selection_agent(selected: Sequence[SkillInstance]) -> str | None:
    """The one robot every selected skill belongs to (None if none or several)."""
    agents = {skill.agent for skill in selected}
    return agents.pop() if len(agents) == 1 else None


def legal_skill_actions(picture: Picture, selected: Sequence[SkillInstance]) -> set[SkillAction]:
    """The skill actions the server would accept for ``selected`` now."""
    if not selected:
        return set()
    legal = _edit_actions(picture, selected) | _unsync_actions(picture, selected)
    if len(selected) == 1 and failure_refusal(selected[0], "retried") is None:
        legal |= {SkillAction.RETRY, SkillAction.SKIP}
    if _barrier_ok(picture, selected):
        legal.add(SkillAction.BARRIER)
    barriers = {b.id: b for s in selected if (b := picture.barrier_of(s.id)) is not None}
    members = [m for b in barriers.values() for m in picture.skills(b.skill_ids)]
    if barriers and all(member_refusal(m, "leave its barrier") is None for m in members):
        legal.add(SkillAction.DELETE_BARRIER)
    return legal


def _edit_actions(picture: Picture, selected: Sequence[SkillInstance]) -> set[SkillAction]:
    if not all(skill.is_editable for skill in selected):
        return set()
    legal = {SkillAction.DELETE} if _barriers_may_shrink(picture, selected) else set()
    agents = {skill.agent for skill in selected}
    if all(sync_refusal(picture.view(agent)) is None for agent in agents):
        legal.add(SkillAction.SYNC)  # several robots: one team send
    agent = selection_agent(selected)
    if agent is not None:
        ids = [skill.id for skill in picture.view(agent).editable]
        picked = sorted(ids.index(s.id) for s in selected if s.id in ids)
        if picked and picked[0] > 0:
            legal.add(SkillAction.MOVE_UP)
        if picked and picked[-1] < len(ids) - 1:
            legal.add(SkillAction.MOVE_DOWN)
    return legal


def _barriers_may_shrink(picture: Picture, leaving: Sequence[SkillInstance]) -> bool:
    gone = {skill.id for skill in leaving}
    barriers = {b.id: b for s in leaving if (b := picture.barrier_of(s.id)) is not None}
    staying = [i for b in barriers.values() for i in b.skill_ids if i not in gone]
    return staying_refusal(picture.skills(staying)) is None


def _unsync_actions(picture: Picture, selected: Sequence[SkillInstance]) -> set[SkillAction]:
    agent = selection_agent(selected)
    if agent is None:
        return set()
    task = picture.view(agent)
    # On the robot, or being uploaded to it: what a take-back can start from.
    sent = {skill.id: index for index, skill in enumerate(task.skills[: task.editable_start])}
    if not all(skill.id in sent for skill in selected):
        return set()
    first = min(sent[skill.id] for skill in selected)
    return {SkillAction.UNSYNC} if take_back_refusal(task, first) is None else set()


def _barrier_ok(picture: Picture, selected: Sequence[SkillInstance]) -> bool:
    if len(selected) < 2 or len({skill.agent for skill in selected}) != len(selected):
        return False
    if any(member_refusal(s, "join a barrier") is not None for s in selected):
        return False
    if any(picture.barrier_of(skill.id) is not None for skill in selected):
        return False
    tasks = {agent: [s.id for s in picture.view(agent).skills] for agent in picture.agents}
    groups = [*(b.skill_ids for b in picture.barriers), [s.id for s in selected]]
    return find_deadlock(tasks, groups) is None


def legal_robot_actions(task: TaskView, executor: ExecutorState) -> set[RobotAction]:
    """The robot actions that can work on ``task``'s robot, reporting ``executor``, now."""
    legal: set[RobotAction] = set()
    if sync_refusal(task) is None:
        legal.add(RobotAction.SYNC_ALL)
    if take_back_refusal(task, None) is None:
        legal.add(RobotAction.UNSYNC_ALL)
    return legal | _control_actions(task, executor)


def _control_actions(task: TaskView, executor: ExecutorState) -> set[RobotAction]:
    active = [s for s in task.synced if s.status.is_active]
    pending = any(not s.status.is_final for s in task.synced)
    paused = executor is ExecutorState.PAUSED or any(s.status is S.PAUSED for s in active)
    started = executor.started
    moving = any(s.status in (S.RUNNING, S.SYNCWAITING) for s in active)
    legal: set[RobotAction] = set()
    if pending and not started and not paused:
        legal.add(RobotAction.START)
    if (started or moving) and not paused:
        legal.add(RobotAction.PAUSE)
    if paused:
        legal.add(RobotAction.RESUME)
    if active or started or paused:
        legal.add(RobotAction.STOP)
    return legal
