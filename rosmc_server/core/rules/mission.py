"""The mission: one object that owns the state and accepts or refuses every change.

Each public operation validates its request completely, then commits exactly
one :class:`MissionEvent` that increments the revision. A refused request
raises a :class:`RosmcError` and leaves the mission as it was. Clock and id
generation are injected so tests and replays are deterministic.
"""

from __future__ import annotations

import secrets
import time
from collections.abc import Callable, Mapping, Sequence

from ..collector import collector_paused
from ..errors import RuleViolation, StaleRevision
from ..live.updates import apply_event
from ..model.changes import Change, EventKind, MissionEvent, Proposal, SkillMove
from ..model.model import SkillStatus, TaskMarker
from ..model.state import MissionContent, MissionState
from ..robots.reconcile import Reconciliation, RobotSkill, plan_reconcile
from ..skills.library import Library
from ..skills.params import Pose
from ..validation import check_skill_count
from ..views.vocabulary import ROBOT_EVENTS
from . import barriers, editing, execution, markers, team
from .replacing import loaded_tasks, require_robots_idle
from .site_guard import SiteGuard
from .undo import UndoHistory

IdFactory = Callable[[str], str]


def random_ids(prefix: str) -> str:
    """Short random ids like ``drone-3fa9c1``: easy to type, unique in practice."""
    return f"{prefix}-{secrets.token_hex(3)}"


class Mission:
    """The authoritative mission of a team, as the mission server holds it.

    Not thread-safe: an adapter that calls it from several threads serializes
    the calls behind one lock.
    """

    def __init__(
        self,
        library: Library,
        content: MissionContent | None = None,
        revision: int = 0,
        clock: Callable[[], float] = time.time,
        new_id: IdFactory = random_ids,
    ) -> None:
        self.library = library
        self.state = MissionState(content or MissionContent.empty(library), revision)
        self._clock = clock
        self._new_id = new_id
        self.operator_revision = revision
        # The site skill targets are checked against (the server hands it each new map).
        self.site = SiteGuard()
        self.history = UndoHistory()

    @property
    def revision(self) -> int:
        """Increments by one with every accepted change."""
        return self.state.revision

    # -- blueprint editing ---------------------------------------------------
    def add_skill(
        self,
        agent: str,
        skill: str,
        params: Mapping[str, object] | None = None,
        *,
        bindings: Mapping[str, str] | None = None,
        label: str = "",
        index: int | None = None,
        timeout: float = 0.0,
        max_retries: int = 0,
        base_revision: int | None = None,
    ) -> MissionEvent:
        """Add a skill with library defaults for every parameter not given."""
        self._check_revision(base_revision)
        proposal = editing.plan_add_skill(
            self.state,
            self.library,
            self._unique_id(agent),
            agent,
            skill,
            params or {},
            bindings or {},
            label,
            index,
            timeout,
            max_retries,
        )
        return self._commit(self._on_site(proposal))

    def edit_skill(
        self,
        skill_id: str,
        params: Mapping[str, object] | None = None,
        *,
        bindings: Mapping[str, str | None] | None = None,
        label: str | None = None,
        timeout: float | None = None,
        max_retries: int | None = None,
        base_revision: int | None = None,
    ) -> MissionEvent:
        """Change a blueprint skill's parameters, bindings, label or options."""
        self._check_revision(base_revision)
        proposal = editing.plan_edit_skill(
            self.state,
            self.library,
            skill_id,
            params or {},
            bindings or {},
            label,
            timeout,
            max_retries,
        )
        return self._commit(self._on_site(proposal))

    def delete_skills(
        self, skill_ids: Sequence[str], *, base_revision: int | None = None
    ) -> MissionEvent:
        """Delete blueprint skills."""
        self._check_revision(base_revision)
        return self._commit(editing.plan_delete_skills(self.state, skill_ids))

    def reorder(
        self, agent: str, order: Sequence[str], *, base_revision: int | None = None
    ) -> MissionEvent:
        """Give an agent's editable blueprint a new order."""
        self._check_revision(base_revision)
        with collector_paused():
            return self._commit(editing.plan_reorder(self.state, agent, order))

    def move_skills(
        self, agent: str, moves: Sequence[SkillMove], *, base_revision: int | None = None
    ) -> MissionEvent:
        """Move skills within an agent's editable blueprint, one after the other."""
        self._check_revision(base_revision)
        with collector_paused():
            return self._commit(editing.plan_move_skills(self.state, agent, moves))

    # -- synchronization and execution ------------------------------------------
    def synchronize(
        self,
        agent: str,
        upto_id: str | None = None,
        *,
        base_revision: int | None = None,
    ) -> MissionEvent:
        """Start uploading a prefix of the agent's blueprint to its robot."""
        self._check_revision(base_revision)
        return self._commit(execution.plan_synchronize(self.state, agent, upto_id))

    def synchronize_team(
        self, uploads: team.TeamUploads | None = None, *, base_revision: int | None = None
    ) -> MissionEvent:
        """Start uploading several robots' blueprints in one change (None: every robot's all)."""
        self._check_revision(base_revision)
        if uploads is None:
            uploads = team.robots_with_blueprints(self.state, list(self.state.agents))
        return self._commit(team.plan_synchronize_team(self.state, uploads))

    def confirm_synchronized(self, agent: str, skill_ids: Sequence[str]) -> MissionEvent:
        """The robot acknowledged the upload of these skills."""
        return self._commit(execution.plan_confirm_sync(self.state, agent, skill_ids))

    def decline_synchronize(
        self, agent: str, skill_ids: Sequence[str], reason: str
    ) -> MissionEvent:
        """The robot refused these uploads, or cannot be reached."""
        return self._commit(execution.plan_decline_sync(self.state, agent, skill_ids, reason))

    def unsynchronize(
        self,
        agent: str,
        from_id: str | None = None,
        *,
        base_revision: int | None = None,
    ) -> MissionEvent:
        """Take back ``from_id`` (None: all that may come back) and the later sent skills:
        cancel an unanswered upload, or ask the robot to give back its not-started skills
        (:func:`~.execution.plan_take_back`, the rule the GUIs enable *Take back* by)."""
        self._check_revision(base_revision)
        return self._commit(execution.plan_take_back(self.state, agent, from_id))

    def cancel_uploads(
        self, agent: str, from_id: str | None = None, *, base_revision: int | None = None
    ) -> MissionEvent:
        """Give up on the agent's unanswered uploads (from ``from_id`` on, if it is one of
        them); they return to the blueprint."""
        self._check_revision(base_revision)
        return self._commit(execution.plan_cancel_uploads(self.state, agent, from_id))

    def confirm_unsynchronized(self, agent: str, removed_ids: Sequence[str]) -> MissionEvent:
        """The robot removed ``removed_ids`` (the others had started)."""
        return self._commit(execution.plan_confirm_unsync(self.state, agent, removed_ids))

    def report_status(
        self,
        skill_id: str,
        status: SkillStatus,
        *,
        attempt: int | None = None,
        text: str = "",
        stamp: float | None = None,
        started: float = 0.0,
        finished: float = 0.0,
    ) -> MissionEvent:
        """A robot's status report for one of its synchronized skills.

        ``started``/``finished`` are the robot's own times for the skill, if it gives them.
        """
        when = self._clock() if stamp is None else stamp
        return self._commit(
            execution.plan_report(
                self.state, skill_id, status, attempt, text, when, started, finished
            )
        )

    def stop(self, agent: str, *, base_revision: int | None = None) -> MissionEvent:
        """The agent's active skill goes back to IDLE_SYNCHRONIZED."""
        self._check_revision(base_revision)
        return self._commit(execution.plan_stop(self.state, agent))

    def retry(self, skill_id: str, *, base_revision: int | None = None) -> MissionEvent:
        """Run a failed skill again as a fresh instance right after it."""
        self._check_revision(base_revision)
        agent, _ = self.state.locate(skill_id)
        check_skill_count(self.state.skill_count + 1)
        return self._commit(execution.plan_retry(self.state, skill_id, self._unique_id(agent)))

    def skip(self, skill_id: str, *, base_revision: int | None = None) -> MissionEvent:
        """Leave a failed skill behind."""
        self._check_revision(base_revision)
        return self._commit(execution.plan_skip(self.state, skill_id))

    def reconcile(
        self, agent: str, robot_queue: Sequence[RobotSkill]
    ) -> tuple[MissionEvent | None, Reconciliation]:
        """Adopt the statuses a robot's snapshot shows; None if nothing differs."""
        result = plan_reconcile(self.state, agent, robot_queue)
        event = None if result.proposal is None else self._commit(result.proposal)
        return event, result

    # -- barriers ------------------------------------------------------------
    def add_barrier(
        self, skill_ids: Sequence[str], *, base_revision: int | None = None
    ) -> MissionEvent:
        """Make skills on distinct agents start together."""
        self._check_revision(base_revision)
        new_id = self._unique_id("barrier")
        return self._commit(barriers.plan_add_barrier(self.state, skill_ids, new_id))

    def delete_barrier(self, barrier_id: str, *, base_revision: int | None = None) -> MissionEvent:
        """Remove a barrier whose skills have not started."""
        self._check_revision(base_revision)
        return self._commit(barriers.plan_delete_barrier(self.state, barrier_id))

    # -- task markers ----------------------------------------------------------
    def add_marker(self, marker: TaskMarker, *, base_revision: int | None = None) -> MissionEvent:
        """Add a task marker (an empty name gets a generated one)."""
        self._check_revision(base_revision)
        return self._commit(markers.plan_add_marker(self.state, marker))

    def move_marker(
        self,
        name: str,
        pose: Pose,
        vertices: Sequence[Pose] = (),
        *,
        base_revision: int | None = None,
    ) -> MissionEvent:
        """Move a task marker; bound parameters follow."""
        self._check_revision(base_revision)
        proposal = markers.plan_move_marker(self.state, self.library, name, pose, vertices)
        return self._commit(self._on_site(proposal))

    def rename_marker(
        self, name: str, new_name: str, *, base_revision: int | None = None
    ) -> MissionEvent:
        """Rename a task marker; bindings follow."""
        self._check_revision(base_revision)
        return self._commit(markers.plan_rename_marker(self.state, name, new_name))

    def delete_marker(self, name: str, *, base_revision: int | None = None) -> MissionEvent:
        """Delete a task marker no skill is bound to."""
        self._check_revision(base_revision)
        return self._commit(markers.plan_delete_marker(self.state, name))

    # -- whole missions ----------------------------------------------------------
    def new_mission(
        self, *, keep_markers: bool = True, base_revision: int | None = None
    ) -> MissionEvent:
        """Start over with empty tasks (and markers unless ``keep_markers``)."""
        self._check_revision(base_revision)
        self._require_robots_idle("start a new mission")
        content = MissionContent.empty(self.library)
        if keep_markers:
            content.markers = {m.name: m for m in self.state.markers}
        return self._commit(
            Proposal(
                EventKind.MISSION_REPLACED,
                "",
                "new mission",
                Change(replacement=content),
            )
        )

    def load(
        self, content: MissionContent, source: str, *, base_revision: int | None = None
    ) -> MissionEvent:
        """Replace the mission with a loaded one (checked by persistence).

        Skills the file shows as synchronized but unfinished return to the
        blueprint: no robot holds them now. SUCCESS and FAILURE stay as logs.
        """
        self._check_revision(base_revision)
        self._require_robots_idle("load a mission")
        tasks = loaded_tasks(content.tasks)
        loaded = MissionContent(
            content.library, tasks, dict(content.barriers), dict(content.markers)
        )
        return self._commit(
            self._on_site(
                Proposal(
                    EventKind.MISSION_REPLACED,
                    "",
                    f"mission loaded from {source}",
                    Change(replacement=loaded),
                )
            )
        )

    def undo(self, revision: int = 0, *, base_revision: int | None = None) -> MissionEvent:
        """Take back the edit made at ``revision`` (0: the latest) as a new change."""
        self._check_revision(base_revision)
        return self._commit(self.history.plan_undo(self.state, revision or self.history.latest()))

    def replay(self, event: MissionEvent) -> None:
        """Apply a journaled event; it must be the next revision (see :func:`apply_event`)."""
        self._take(event)

    # -- internals ---------------------------------------------------------------------------
    def _commit(self, proposal: Proposal) -> MissionEvent:
        event = MissionEvent(
            self.state.revision + 1,
            proposal.kind,
            proposal.agent,
            proposal.summary,
            self._clock(),
            proposal.change,
            proposal.undoes,
        )
        self._take(event)
        return event

    def _take(self, event: MissionEvent) -> None:
        """Apply ``event`` with the one applier, keeping the undo history and the operator
        revision as it goes (the server's own changes and a resume's alike)."""
        inverse = self.history.inverse(self.state, event.kind, event.change)
        apply_event(self.state, event, describe=False)
        if event.kind not in ROBOT_EVENTS:
            self.operator_revision = event.revision
        self.history.keep(self.state, event, inverse)

    def _on_site(self, proposal: Proposal) -> Proposal:
        """``proposal`` if the targets it sets suit the known site; RuleViolation if not."""
        self.site.check(self.library, self.state, proposal.change)
        return proposal

    def _check_revision(self, base_revision: int | None) -> None:
        """Refuse a request made before another operator's change (or from the future).

        Robots report progress all the time; that bumps the revision but does not
        make an operator's view stale, because the mission rules already refuse
        what progress forbids (editing a skill that has started, say).
        """
        if base_revision is None:
            return
        if base_revision < self.operator_revision or base_revision > self.state.revision:
            raise StaleRevision(base_revision, self.state.revision)

    def _unique_id(self, prefix: str) -> str:
        for _ in range(100):
            candidate = self._new_id(prefix)
            if not self.state.has_skill(candidate) and not self.state.has_barrier(candidate):
                return candidate
        raise RuleViolation("could not find a free id; the id factory keeps repeating itself")

    def _require_robots_idle(self, action: str) -> None:
        require_robots_idle(self.state.content().tasks.values(), action)
