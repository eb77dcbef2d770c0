"""The SynchronizeTeam service (``/rosmc/synchronize_team``): several robots in one change.

Every listed robot must be reachable and have what it is asked to send; if one cannot,
the request is refused with that robot's sentence and no robot is sent anything. Accepted,
it is one revision and one ``SYNC_REQUESTED`` event; the ground link then sends each robot
its own upload (with the barriers it now shares with the others).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from ..conversions.request_fields import base_of
from ..core import InvalidRequest, MissionEvent
from ..core.rules.advice import unsynced_partners
from ..core.rules.team import robots_with_blueprints
from .server_host import ServerHost


def uploads_from_request(server: ServerHost, req: Any) -> dict[str, str | None]:
    """Robot -> last skill to send (None: all), from the request's lists; InvalidRequest if bad."""
    agents, uptos = list(req.agents), list(req.upto_ids)
    if uptos and len(uptos) != len(agents):
        raise InvalidRequest(
            f"give one upto id per robot or none ({len(agents)} robots, {len(uptos)} ids)"
        )
    if not agents:
        return robots_with_blueprints(server.mission.state, list(server.library.dynamic_agents))
    uploads: dict[str, str | None] = {}
    for index, agent in enumerate(agents):
        if agent in uploads:
            raise InvalidRequest(f"robot '{agent}' is listed twice")
        uploads[agent] = (uptos[index] if uptos else "") or None
    return uploads


def synchronize_team(
    server: ServerHost,
    require_link: Callable[[str], None],
    queued_note: Callable[[list[str]], str],
    req: Any,
    resp: Any,
) -> MissionEvent:
    """Answer one SynchronizeTeam request (raises a RosmcError to refuse it)."""
    with server.locked():
        uploads = uploads_from_request(server, req)
        for agent in uploads:
            require_link(agent)
        event = server.apply(lambda m: m.synchronize_team(uploads, base_revision=base_of(req)))
        assert event is not None
        resp.agents = list(uploads)
        resp.skill_ids = [placed.skill.id for placed in event.change.put_skills]
        partners = unsynced_partners(server.mission.state, resp.skill_ids)
        warnings = [f"warning: {partner.sentence()}" for partner in partners]
        resp.note = "; ".join(part for part in (queued_note(list(uploads)), *warnings) if part)
    return event
