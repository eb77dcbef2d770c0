"""The operator services of the mission server: one per operation.

Advertises every service of :data:`rosmc_server.interface.SERVICES` under
``/rosmc/`` (types ``rosmc/<Name>``). Each handler checks its request, runs
the operation through :meth:`MissionServer.apply` and answers with the new
revision; a refused request answers with an error code and one sentence, and
the mission is unchanged. No handler lets an exception reach rospy: a server
fault is logged with its traceback and answered as an INTERNAL error.
Services never wait for robots: a command for a robot out of contact is accepted and
waits for it (:mod:`rosmc_server.core.robots.waiting`), and the answer's note says so.
"""

from __future__ import annotations

import contextlib
import logging
import re
from collections.abc import Callable
from typing import Any

import rosmc.srv as srv
import rospy
from rosmc.msg import ErrorCode

from .. import interface
from ..conversions import (
    library_to_msg,
    marker_from_msg,
    moves_from_msgs,
    params_from_msgs,
    policy_from_request,
    pose_from_msg,
)
from ..conversions.move_fields import order_from_field
from ..conversions.request_fields import base_of, insert_index_from_msg
from ..core import (
    EventKind,
    InvalidRequest,
    LibraryError,
    Mission,
    MissionEvent,
    MissionFileError,
    NotFound,
    NotPermitted,
    RosmcError,
    RuleViolation,
    StaleRevision,
    Unavailable,
)
from ..core.robots.commands import CommandKind, CommandSpec
from ..core.robots.link import LinkStatus
from ..core.robots.waiting import check_link_command, queued_notes
from ..core.rules.advice import unsynced_partners
from ..core.rules.execution import take_back_command
from ..core.skills.policy import options_argument
from .caller_id import caller_id
from .server_host import ServerHost
from .team_sync import synchronize_team
from .whole_mission import WholeMissionServices

_log = logging.getLogger(__name__)

_CODES: tuple[tuple[type[RosmcError], int], ...] = (
    (StaleRevision, ErrorCode.CONFLICT),
    (NotFound, ErrorCode.NOT_FOUND),
    (NotPermitted, ErrorCode.FORBIDDEN),
    (RuleViolation, ErrorCode.RULE),
    (Unavailable, ErrorCode.UNAVAILABLE),
    (InvalidRequest, ErrorCode.INVALID),
    (MissionFileError, ErrorCode.INVALID),
    (LibraryError, ErrorCode.INVALID),
)

_CONTROL = {
    srv.ControlRequest.START: CommandKind.START,
    srv.ControlRequest.PAUSE: CommandKind.PAUSE,
    srv.ControlRequest.RESUME: CommandKind.RESUME,
    srv.ControlRequest.STOP: CommandKind.STOP,
}


READ_ONLY = frozenset({"get_mission", "get_library"})
"""Operations every node may call, whatever the operator allow-list says."""


def error_code(error: RosmcError) -> int:
    """The ErrorCode constant for a core error."""
    for kind, code in _CODES:
        if isinstance(error, kind):
            return code
    return int(ErrorCode.INVALID)


# Line breaks and other control characters an error may quote from the request.
_CONTROL_CHARS = re.compile(r"[\x00-\x1f\x7f\x85\u2028\u2029]")


def notes(*parts: str) -> str:
    """The non-empty parts, as one line."""
    return "; ".join(part for part in parts if part)


def one_line(message: str) -> str:
    """The message with quoted control characters escaped, so it stays one line."""
    return _CONTROL_CHARS.sub(lambda match: repr(match.group())[1:-1], message)


def _text(value: str, what: str) -> str:
    if not value.strip():
        raise InvalidRequest(f"{what} is empty")
    return value


class OperatorServices:
    """Request handlers of every operator service."""

    def __init__(self, server: ServerHost) -> None:
        self._server = server
        self._library_msg = library_to_msg(server.library)
        self._whole = WholeMissionServices(server)
        self._services: list[rospy.Service] = []

    def advertise(self) -> None:
        """Advertise every operator service."""
        for operation, type_name in interface.SERVICES.items():
            service_class = getattr(srv, type_name)
            if operation == "get_mission":  # answered with the shared, serialized snapshot
                callback: Callable[[Any], Any] = self._whole.get_mission
            else:
                handler = getattr(self, f"_{operation}", None) or getattr(self._whole, operation)
                callback = self._answer(handler, service_class._response_class, operation)
            self._services.append(
                rospy.Service(interface.service_name(operation), service_class, callback)
            )

    def _answer(
        self, handler: Callable[[Any, Any], MissionEvent | None], response_class: Any, name: str
    ) -> Callable[[Any], Any]:
        def callback(request: Any) -> Any:
            response = response_class()
            try:
                if name not in READ_ONLY:
                    self._server.config.operators.check(caller_id(request), name)
                event = handler(request, response)
            except RosmcError as error:
                self._fail(response, error_code(error), one_line(str(error)))
            except Exception:  # a server fault must not reach the caller as a stack trace
                _log.exception("service %s failed", name)
                self._fail(
                    response, ErrorCode.INTERNAL, f"internal error in {name}; see the server log"
                )
            else:
                if hasattr(response, "revision"):
                    response.revision = event.revision if event else self._server.mission.revision
            return response

        return callback

    def _fail(self, response: Any, code: int, message: str) -> None:
        if hasattr(response, "error"):
            response.error_code = code
            response.error = message
            with contextlib.suppress(Unavailable):  # after a journal failure: nothing to name
                response.revision = self._server.mission.revision

    def _apply(self, operation: Callable[[Mission], MissionEvent]) -> MissionEvent:
        event = self._server.apply(operation)
        assert event is not None
        return event

    def _require_link(self, agent: str, kind: CommandKind | None = CommandKind.UPLOAD) -> None:
        """``agent`` has a robot link, and room for a command of ``kind`` (None: one that
        adds no work): the core's rule (:func:`~..core.robots.waiting.check_link_command`)."""
        _text(agent, "the agent name")
        link = self._server.link
        check_link_command(self._server.library, agent, kind, lambda: link.waiting_work(agent))

    # -- blueprint ----------------------------------------------------------------
    def _add_skill(self, req: Any, resp: Any) -> MissionEvent:
        values, bindings = params_from_msgs(req.parameters)
        event = self._apply(
            lambda m: m.add_skill(
                _text(req.agent, "the agent name"),
                _text(req.skill, "the skill name"),
                values,
                bindings=bindings,
                label=req.label,
                index=insert_index_from_msg(req.index),
                timeout=req.timeout,
                max_retries=req.max_retries,
                base_revision=base_of(req),
            )
        )
        resp.skill_id = event.change.put_skills[0].skill.id
        return event

    def _edit_skill(self, req: Any, resp: Any) -> MissionEvent:
        values, bindings = params_from_msgs(req.parameters)
        return self._apply(
            lambda m: m.edit_skill(
                _text(req.skill_id, "the skill id"),
                values,
                bindings=dict(bindings),
                label=req.label or None,
                timeout=req.timeout if req.set_options else None,
                max_retries=req.max_retries if req.set_options else None,
                base_revision=base_of(req),
            )
        )

    def _delete_skills(self, req: Any, resp: Any) -> MissionEvent:
        return self._apply(lambda m: m.delete_skills(req.skill_ids, base_revision=base_of(req)))

    def _reorder_skills(self, req: Any, resp: Any) -> MissionEvent:
        agent = _text(req.agent, "the agent name")
        base = base_of(req)
        if req.moves:
            if req.order:
                raise InvalidRequest("give either a new order or moves, not both")
            moves = moves_from_msgs(req.moves)
            return self._apply(lambda m: m.move_skills(agent, moves, base_revision=base))
        order = order_from_field(req.order)
        return self._apply(lambda m: m.reorder(agent, order, base_revision=base))

    # -- synchronization and execution ---------------------------------------------
    def _synchronize(self, req: Any, resp: Any) -> MissionEvent:
        with self._server.locked():
            self._require_link(req.agent)
            event = self._apply(
                lambda m: m.synchronize(req.agent, req.upto_id or None, base_revision=base_of(req))
            )
            resp.skill_ids = [placed.skill.id for placed in event.change.put_skills]
            partners = unsynced_partners(self._server.mission.state, resp.skill_ids)
            resp.note = notes(
                self._queued_note([req.agent]), *(f"warning: {p.sentence()}" for p in partners)
            )
        return event

    def _synchronize_team(self, req: Any, resp: Any) -> MissionEvent:
        return synchronize_team(self._server, self._require_link, self._queued_note, req, resp)

    def _unsynchronize(self, req: Any, resp: Any) -> MissionEvent:
        # Take back: the core decides whether it cancels an unanswered upload or asks the
        # robot (plan_take_back), and whether that needs room on the link.
        agent = _text(req.agent, "the agent name")
        with self._server.locked():
            state = self._server.mission.state
            self._require_link(agent, take_back_command(state, agent))
            event = self._apply(
                lambda m: m.unsynchronize(agent, req.from_id or None, base_revision=base_of(req))
            )
            if event.kind is EventKind.UNSYNC_REQUESTED:
                resp.note = self._queued_note([agent])
        resp.skill_ids = [placed.skill.id for placed in event.change.put_skills]
        return event

    def _queued_note(self, agents: list[str]) -> str:
        """Say so when a command waits for robots out of contact (never heard, or link down)."""
        reports = [(agent, self._server.link.details(agent)[0]) for agent in agents]
        waiting = [
            (agent, report.status is LinkStatus.UNKNOWN, report.last_heard)
            for agent, report in reports
            if report.status is not LinkStatus.UP
        ]
        return notes(*queued_notes(waiting))

    def _control(self, req: Any, resp: Any) -> None:
        if req.command not in _CONTROL:
            raise InvalidRequest(f"unknown control command {req.command}")
        agents = [req.agent] if req.agent else list(self._server.library.dynamic_agents)
        with self._server.locked():
            for agent in agents:
                self._require_link(agent, None)
            for agent in agents:
                self._server.link.send(CommandSpec(agent, _CONTROL[req.command]))
            resp.note = self._queued_note(agents)
        resp.agents = agents
        return None

    def _set_lost_link_policy(self, req: Any, resp: Any) -> None:
        agent = _text(req.agent, "the agent name")
        policy = policy_from_request(req).checked(self._server.library, agent)
        with self._server.locked():
            self._require_link(agent, None)
            argument = options_argument(policy)
            self._server.link.send(CommandSpec(agent, CommandKind.SET_OPTIONS, argument=argument))
            resp.note = self._queued_note([agent])
        return None

    def _retry_skill(self, req: Any, resp: Any) -> MissionEvent:
        with self._server.locked():
            agent, _ = self._server.mission.state.locate(_text(req.skill_id, "the skill id"))
            self._require_link(agent, CommandKind.RETRY)
            event = self._apply(lambda m: m.retry(req.skill_id, base_revision=base_of(req)))
        resp.new_skill_id = event.change.put_skills[1].skill.id
        return event

    def _skip_skill(self, req: Any, resp: Any) -> MissionEvent:
        with self._server.locked():
            agent, _ = self._server.mission.state.locate(_text(req.skill_id, "the skill id"))
            self._require_link(agent, CommandKind.SKIP)
            return self._apply(lambda m: m.skip(req.skill_id, base_revision=base_of(req)))

    # -- barriers and markers ---------------------------------------------------
    def _add_barrier(self, req: Any, resp: Any) -> MissionEvent:
        event = self._apply(lambda m: m.add_barrier(req.skill_ids, base_revision=base_of(req)))
        resp.barrier_id = event.change.put_barriers[0].id
        return event

    def _delete_barrier(self, req: Any, resp: Any) -> MissionEvent:
        barrier_id = _text(req.barrier_id, "the barrier id")
        return self._apply(lambda m: m.delete_barrier(barrier_id, base_revision=base_of(req)))

    def _add_task_marker(self, req: Any, resp: Any) -> MissionEvent:
        marker = marker_from_msg(req.marker)
        event = self._apply(lambda m: m.add_marker(marker, base_revision=base_of(req)))
        resp.name = event.change.put_markers[0].name
        return event

    def _move_task_marker(self, req: Any, resp: Any) -> MissionEvent:
        pose = pose_from_msg(req.pose)
        vertices = [pose_from_msg(v) for v in req.vertices]
        name = _text(req.name, "the marker name")
        return self._apply(
            lambda m: m.move_marker(name, pose, vertices, base_revision=base_of(req))
        )

    def _rename_task_marker(self, req: Any, resp: Any) -> MissionEvent:
        name = _text(req.name, "the marker name")
        return self._apply(
            lambda m: m.rename_marker(name, req.new_name, base_revision=base_of(req))
        )

    def _delete_task_marker(self, req: Any, resp: Any) -> MissionEvent:
        name = _text(req.name, "the marker name")
        return self._apply(lambda m: m.delete_marker(name, base_revision=base_of(req)))

    def _undo_edit(self, req: Any, resp: Any) -> MissionEvent:
        event = self._apply(lambda m: m.undo(req.undo_revision, base_revision=base_of(req)))
        resp.summary = event.summary
        return event

    # -- whole missions -------------------------------------------------------------
    def _new_mission(self, req: Any, resp: Any) -> MissionEvent:
        return self._apply(
            lambda m: m.new_mission(keep_markers=req.keep_markers, base_revision=base_of(req))
        )

    def _get_library(self, req: Any, resp: Any) -> None:
        resp.library = self._library_msg
        return None
