"""The Python client of the mission server: operator services, events and agent states.

:class:`MissionClient` calls the operator services; :class:`AsyncMissionClient` runs
those calls on a worker thread for GUIs. :class:`MissionFollower` keeps a
:class:`~rosmc_server.core.live.mirror.MissionMirror` (a live copy of the mission) current from
the events, agent states and snapshots; :class:`MissionWatch` queues the raw events
(``rosmc watch``). All speak core objects and raise one error family, rooted in
:class:`RosmcError`: the server's refusals (:class:`RevisionConflict` for a stale
revision, ``NotFound``, ``InvalidRequest``, ``RuleViolation``, ... from
:mod:`rosmc_server.core`) and :class:`ServerUnavailable` when no server answers. Catch
``RosmcError`` for all of them; ``str(error)`` is one sentence an operator can read.
"""

from ...conversions import agent_status_from_msg, agent_statuses_from_msg, library_from_msg
from ...core.errors import RosmcError, ServerUnavailable
from ..node_setup import init_node
from .follow import MissionFollower
from .mission_client import MissionClient
from .results import (
    BarrierAdded,
    ControlCommand,
    ControlSent,
    MarkerAdded,
    MissionSaved,
    Result,
    RevisionConflict,
    SkillAdded,
    SkillRetried,
    TeamTransferred,
    Transferred,
)
from .science import ScienceWatch
from .site import SiteWatch
from .watch import MissionWatch, identify
from .worker import AsyncMissionClient, Outcome

__all__ = [
    "AsyncMissionClient",
    "BarrierAdded",
    "ControlCommand",
    "ControlSent",
    "MarkerAdded",
    "MissionClient",
    "MissionFollower",
    "MissionSaved",
    "MissionWatch",
    "Outcome",
    "Result",
    "RevisionConflict",
    "RosmcError",
    "ScienceWatch",
    "ServerUnavailable",
    "SiteWatch",
    "SkillAdded",
    "SkillRetried",
    "TeamTransferred",
    "Transferred",
    "agent_status_from_msg",
    "agent_statuses_from_msg",
    "identify",
    "init_node",
    "library_from_msg",
]
