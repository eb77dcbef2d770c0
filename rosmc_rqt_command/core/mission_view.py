"""The GUI thread's picture of the mission: the latest :class:`TaskView` of every robot.

:class:`MissionView` takes :class:`~.view_state.ViewUpdate` values in order (a reset's copy
of the mission, then each update's event applied to it with the one applier,
:func:`~rosmc_server.core.live.updates.apply_event`) and answers the read-only questions panels
ask (which skill has this id, which barrier holds it, what a robot reports). It lives on
the GUI thread only, so nothing here needs a lock.
"""

from __future__ import annotations

from collections.abc import Sequence

from rosmc_server.core import (
    AgentStatus,
    Barrier,
    Library,
    MissionState,
    SkillInstance,
    SkillStatus,
    TaskMarker,
)
from rosmc_server.core.live.updates import apply_event
from rosmc_server.core.model.control import HoldCause
from rosmc_server.core.robots.link import LinkStatus
from rosmc_server.core.rules.legality import TaskView

from . import presentation
from .view_state import ViewUpdate, barrier_tags


class MissionView:
    """The mission as the panels show it (GUI thread only)."""

    def __init__(self) -> None:
        self.revision = -1
        self.library: Library | None = None
        self.library_name = ""
        self.agents: dict[str, TaskView] = {}  # each over its task in _state
        self._state: MissionState | None = None  # the GUI thread's own copy
        self.barriers: tuple[Barrier, ...] = ()
        self.markers: dict[str, TaskMarker] = {}
        self.statuses: dict[str, AgentStatus] = {}
        self._tags: dict[str, tuple[int, Barrier]] = {}

    @property
    def loaded(self) -> bool:
        """A mission snapshot has arrived."""
        return self.revision >= 0

    def apply(self, update: ViewUpdate) -> None:
        """Take one update (in revision order): a reset's mission, or the event it applied."""
        if update.reset and update.state is not None:
            self._state = update.state
            self.agents = {
                agent: TaskView.live(update.state, agent) for agent in update.state.agents
            }
            self.library_name = update.library
        elif self._state is not None and update.event is not None:
            # before the first snapshot there is nothing to change
            apply_event(self._state, update.event)
            for agent in update.touched:
                self.agents[agent] = TaskView.live(self._state, agent)
        if update.barriers is not None:
            self.barriers = update.barriers
            self._tags = barrier_tags(update.barriers)
        if update.markers is not None:
            self.markers = {marker.name: marker for marker in update.markers}
        for status in update.statuses:
            self.statuses[status.agent] = status
        if update.reset:
            self.revision = update.revision
        elif self.loaded:
            self.revision = max(self.revision, update.revision)

    # -- queries ---------------------------------------------------------------------------
    def skill(self, skill_id: str) -> SkillInstance | None:
        """The skill with this id, if it exists."""
        state = self._state
        return state.skill(skill_id) if state is not None and state.has_skill(skill_id) else None

    def skills(self, skill_ids: Sequence[str]) -> list[SkillInstance]:
        """The skills with these ids that exist, in the given order."""
        return [s for i in skill_ids if (s := self.skill(i)) is not None]

    def barrier_of(self, skill_id: str) -> Barrier | None:
        """The barrier ``skill_id`` belongs to, if any."""
        tag = self._tags.get(skill_id)
        return None if tag is None else tag[1]

    def barrier_number(self, skill_id: str) -> int:
        """The barrier's number as shown ("B1" is 1), 0 if the skill is in none."""
        tag = self._tags.get(skill_id)
        return 0 if tag is None else tag[0]

    def view(self, agent: str) -> TaskView:
        """``agent``'s task (empty if unknown)."""
        return self.agents.get(agent) or TaskView(agent)

    def position(self, skill: SkillInstance) -> int:
        """The skill's index in its robot's task (-1 if it is not there)."""
        for index, other in enumerate(self.view(skill.agent).skills):
            if other.id == skill.id:
                return index
        return -1

    def waiting_on(self, skill: SkillInstance) -> list[str]:
        """Whom ``skill`` waits for at its barrier.

        As its robot reports it while it waits there (``r2 at B3 (arrived, not yet
        confirmed)``, the barrier named by its tag: the robot knows what the ground cannot
        see during a cut), else the robots whose partner skill has not started.
        """
        status = self.statuses.get(skill.agent)
        if (
            status is not None
            and status.waiting_on
            and status.current_skill == skill.id
            and skill.status is SkillStatus.SYNCWAITING
        ):
            barrier = self.barrier_of(skill.id)
            if barrier is None:
                return [status.waiting_on]
            # the robot names the barrier by its id; the operator knows it by its tag
            tag = f" at B{self.barrier_number(skill.id)}"
            return [status.waiting_on.replace(f" at {barrier.id}", tag)]
        barrier = self.barrier_of(skill.id)
        if barrier is None:
            return []
        waiting = []
        for partner in self.skills(barrier.skill_ids):
            if partner.id != skill.id and not partner.status.has_started:
                waiting.append(partner.agent)
        return waiting

    def out_of_contact(self, agent: str) -> bool:
        """The ground cannot hear ``agent``'s robot (never heard, or its link is down)."""
        status = self.statuses.get(agent)
        return status is not None and status.link is not LinkStatus.UP

    def status_text(self, skill: SkillInstance) -> str:
        """The skill's status cell, as every panel shows it."""
        out = self.out_of_contact(skill.agent)
        status = self.statuses.get(skill.agent)
        heard = status.last_heard if out and status is not None else -1.0
        holding = status is not None and status.hold is not HoldCause.NONE
        return presentation.status_text(skill, self.waiting_on(skill), out, heard, holding)

    def bound_markers(self, skills: Sequence[SkillInstance]) -> list[str]:
        """Names of the task markers bound to any of ``skills`` (each once)."""
        names: list[str] = []
        for skill in skills:
            for name in skill.bindings.values():
                if name not in names:
                    names.append(name)
        return names

    def skills_bound_to(self, marker_name: str) -> list[SkillInstance]:
        """Skills with a parameter bound to the marker, robot by robot."""
        return [
            skill
            for view in self.agents.values()
            for skill in view.skills
            if marker_name in skill.bindings.values()
        ]
