""":class:`MissionClient`: every operator operation as a typed Python method."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

from ...conversions import moves_to_msgs, policy_to_request
from ...conversions.move_fields import order_to_field
from ...conversions.request_fields import insert_index_to_msg
from ...core import InvalidRequest, LostLinkPolicy
from ...core.model.changes import SkillMove
from ...core.rules.editing import check_retries, check_timeout
from .connection import raise_for
from .marker_calls import MarkerCalls
from .results import (
    BarrierAdded,
    ControlCommand,
    ControlSent,
    EditUndone,
    MissionSaved,
    Result,
    SkillAdded,
    SkillRetried,
    TeamTransferred,
    Transferred,
)


class MissionClient(MarkerCalls):
    """The Python client of the mission server (command line, GUIs, scripted operators).

    Methods take core-level arguments (agent and skill names, parameter values as
    plain data checked against the library schema, marker bindings) and return a
    :class:`Result` or raise a core :class:`~rosmc_server.core.RosmcError`:
    InvalidRequest, NotFound, RuleViolation, Unavailable (too many commands wait for a robot),
    :class:`RevisionConflict` (a StaleRevision) and :class:`ServerUnavailable`.

    ``revision`` is the latest mission revision the client knows (from
    :meth:`get_mission` and accepted requests). Mutating requests are made against
    it unless ``base_revision`` is given; so a change by someone else since then is
    refused as a conflict. ``retry_on_conflict=True`` instead refetches the mission
    and sends the request once more; use it only where that is safe. One client may
    be shared between threads (calls are serialized).

    Args:
        timeout: Seconds to wait for the server to appear (per connection).
        prefix: Namespace before every service name, e.g. ``/replay`` to read a replay.
    """

    # -- blueprint -------------------------------------------------------------------
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
        retry_on_conflict: bool = False,
    ) -> SkillAdded:
        """Add a skill to ``agent``'s blueprint (appended, or inserted at task ``index``).

        ``params`` maps parameter names to raw values (``12``, ``{"x": 3, "y": 4}``);
        ``bindings`` maps parameter names to task marker names. Unnamed parameters
        take the library default.
        """
        parameters = self._parameters(agent, skill, params or {}, bindings or {})
        response = self._mutate(
            "add_skill",
            base_revision,
            retry_on_conflict,
            agent=agent,
            skill=skill,
            label=label,
            index=insert_index_to_msg(index),
            parameters=parameters,
            timeout=check_timeout(timeout),
            max_retries=check_retries(max_retries),
        )
        self._kinds[response.skill_id] = (agent, skill)
        return SkillAdded(response.revision, response.skill_id)

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
        retry_on_conflict: bool = False,
    ) -> Result:
        """Change a blueprint skill; only what is given changes (``label`` "" or None: kept).

        A parameter given a value loses its marker binding; a binding to ``None``
        or ``""`` unbinds the parameter and keeps its current value.
        """
        fields = self._edit_fields(
            skill_id, dict(params or {}), dict(bindings or {}), timeout, max_retries
        )
        response = self._mutate(
            "edit_skill",
            base_revision,
            retry_on_conflict,
            skill_id=skill_id,
            label=label or "",
            **fields,
        )
        return Result(response.revision)

    def _edit_fields(
        self,
        skill_id: str,
        values: dict[str, object],
        bindings: dict[str, str | None],
        timeout: float | None,
        max_retries: int | None,
    ) -> dict[str, Any]:
        # The wire unbinds a parameter when it gets a value, and sets both options or
        # neither, so what stays as it was is sent with its current value.
        set_options = timeout is not None or max_retries is not None
        unbind = [name for name, marker in bindings.items() if not marker]
        if unbind or (timeout is None) != (max_retries is None):
            current = self.skill(skill_id)
            values.update({name: current.params[name] for name in unbind if name in current.params})
            timeout = current.timeout if timeout is None else timeout
            max_retries = current.max_retries if max_retries is None else max_retries
        agent, skill = self._kind(skill_id)
        marked = {name: marker for name, marker in bindings.items() if marker}
        return {
            "parameters": self._parameters(agent, skill, values, marked),
            "set_options": set_options,
            "timeout": check_timeout(timeout or 0.0),
            "max_retries": check_retries(max_retries or 0),
        }

    def delete_skills(
        self,
        skill_ids: Sequence[str],
        *,
        base_revision: int | None = None,
        retry_on_conflict: bool = False,
    ) -> Result:
        """Delete blueprint skills (and their barrier memberships)."""
        return Result(
            self._mutate(
                "delete_skills", base_revision, retry_on_conflict, skill_ids=list(skill_ids)
            ).revision
        )

    def reorder_skills(
        self,
        agent: str,
        order: Sequence[str] = (),
        *,
        moves: Sequence[tuple[str, int]] = (),
        base_revision: int | None = None,
        retry_on_conflict: bool = False,
    ) -> Result:
        """Give ``agent``'s editable blueprint a new order, as ``order`` or as ``moves``.

        ``order`` is the whole new order (a permutation of its ids); ``moves`` are
        (skill id, index once moved) pairs, applied one after the other, so the request's
        size is the moves', not the task's. The server refuses a request with both.
        """
        wire_moves = moves_to_msgs([SkillMove(skill_id, index) for skill_id, index in moves])
        return Result(
            self._mutate(
                "reorder_skills",
                base_revision,
                retry_on_conflict,
                agent=agent,
                order=order_to_field(order),
                moves=wire_moves,
            ).revision
        )

    # -- synchronization and execution ---------------------------------------------------
    def synchronize(
        self,
        agent: str,
        upto_id: str | None = None,
        *,
        base_revision: int | None = None,
        retry_on_conflict: bool = False,
    ) -> Transferred:
        """Upload ``agent``'s blueprint up to and including ``upto_id`` (None: all of it)."""
        response = self._mutate(
            "synchronize", base_revision, retry_on_conflict, agent=agent, upto_id=upto_id or ""
        )
        return Transferred(response.revision, tuple(response.skill_ids), response.note)

    def synchronize_team(
        self,
        uploads: Mapping[str, str | None] | None = None,
        *,
        base_revision: int | None = None,
        retry_on_conflict: bool = False,
    ) -> TeamTransferred:
        """Upload several robots' blueprints in one change, all or nothing.

        ``uploads`` maps each robot to the last skill to send (None: its whole blueprint);
        None sends every robot's whole blueprint.
        """
        agents = list(uploads or {})
        uptos = [upto or "" for upto in (uploads or {}).values()]
        response = self._mutate(
            "synchronize_team", base_revision, retry_on_conflict, agents=agents, upto_ids=uptos
        )
        return TeamTransferred(
            response.revision, tuple(response.skill_ids), response.note, tuple(response.agents)
        )

    def unsynchronize(
        self,
        agent: str,
        from_id: str | None = None,
        *,
        base_revision: int | None = None,
        retry_on_conflict: bool = False,
    ) -> Transferred:
        """Pull ``from_id`` and every later not-started synchronized skill back (None: all)."""
        response = self._mutate(
            "unsynchronize", base_revision, retry_on_conflict, agent=agent, from_id=from_id or ""
        )
        return Transferred(response.revision, tuple(response.skill_ids), response.note)

    def control(self, command: ControlCommand, agent: str | None = None) -> ControlSent:
        """Start, pause, resume or stop one robot, or every robot (``agent`` None)."""
        response = self._caller.call("control", agent=agent or "", command=int(command))
        raise_for(response, response.revision)
        return ControlSent(response.revision, tuple(response.agents), response.note)

    def set_lost_link_policy(self, agent: str, policy: LostLinkPolicy) -> Result:
        """Set ``agent``'s lost-link policy (what it does when it stops hearing the ground).

        The safe skill's parameters are checked against the library here and on the
        server (those not given take the default). The robot reports the policy in
        force in its agent state (:attr:`AgentStatus.lost_link`). While the robot cannot be
        reached the change waits for contact (a newer one replaces it); Unavailable when
        too many commands already wait.
        """
        parameters = (
            self._parameters(agent, policy.skill, policy.params, {}) if policy.skill else []
        )
        response = self._caller.call(
            "set_lost_link_policy", agent=agent, **policy_to_request(policy, parameters)
        )
        raise_for(response, response.revision)
        return Result(response.revision)

    def retry_skill(
        self, skill_id: str, *, base_revision: int | None = None, retry_on_conflict: bool = False
    ) -> SkillRetried:
        """Retry a FAILURE: a fresh synchronized instance follows it."""
        response = self._mutate("retry_skill", base_revision, retry_on_conflict, skill_id=skill_id)
        return SkillRetried(response.revision, response.new_skill_id)

    def skip_skill(
        self, skill_id: str, *, base_revision: int | None = None, retry_on_conflict: bool = False
    ) -> Result:
        """Skip a FAILURE: the robot continues after it."""
        return Result(
            self._mutate("skip_skill", base_revision, retry_on_conflict, skill_id=skill_id).revision
        )

    # -- barriers (task markers: MarkerCalls) -------------------------------------------
    def add_barrier(
        self,
        skill_ids: Sequence[str],
        *,
        base_revision: int | None = None,
        retry_on_conflict: bool = False,
    ) -> BarrierAdded:
        """Make skills on distinct agents start together."""
        response = self._mutate(
            "add_barrier", base_revision, retry_on_conflict, skill_ids=list(skill_ids)
        )
        return BarrierAdded(response.revision, response.barrier_id)

    def delete_barrier(
        self, barrier_id: str, *, base_revision: int | None = None, retry_on_conflict: bool = False
    ) -> Result:
        """Remove a barrier whose skills have not started."""
        return Result(
            self._mutate(
                "delete_barrier", base_revision, retry_on_conflict, barrier_id=barrier_id
            ).revision
        )

    def undo_edit(
        self,
        revision: int = 0,
        *,
        base_revision: int | None = None,
        retry_on_conflict: bool = False,
    ) -> EditUndone:
        """Undo the edit that produced ``revision`` (0: the latest edit not undone)."""
        response = self._mutate(
            "undo_edit", base_revision, retry_on_conflict, undo_revision=revision
        )
        return EditUndone(response.revision, response.summary)

    # -- whole missions ----------------------------------------------------------------
    def new_mission(
        self,
        keep_markers: bool = True,
        *,
        base_revision: int | None = None,
        retry_on_conflict: bool = False,
    ) -> Result:
        """Start an empty mission (refused while robots hold unfinished skills)."""
        return Result(
            self._mutate(
                "new_mission", base_revision, retry_on_conflict, keep_markers=keep_markers
            ).revision
        )

    def save_mission(self, path: str = "", *, return_document: bool | None = None) -> MissionSaved:
        """Save the mission: with ``path``, written on the server's host; else returned.

        ``return_document`` (default: only without a path) asks for the YAML document in
        the answer too; a large mission saved on the server need not travel back.
        """
        wanted = not path if return_document is None else return_document
        response = self._caller.call("save_mission", path=path, return_document=wanted)
        raise_for(response, response.revision)
        return MissionSaved(response.revision, response.document, response.path_written)

    def load_mission(
        self,
        document: str | None = None,
        path: str | None = None,
        *,
        base_revision: int | None = None,
        retry_on_conflict: bool = False,
    ) -> Result:
        """Replace the mission with a saved ``document``, or a file at ``path`` on the server."""
        if (document is None) == (path is None):
            raise InvalidRequest("give exactly one of a document and a path to load")
        response = self._mutate(
            "load_mission",
            base_revision,
            retry_on_conflict,
            document=document or "",
            path=path or "",
        )
        return Result(response.revision)
