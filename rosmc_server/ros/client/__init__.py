"""The Python client of the mission server: operator services, events and agent states.

:class:`MissionClient` calls the operator services; :class:`MissionWatch`
subscribes to the mission events and agent states (after :func:`init_node`).
Both speak core objects and raise the core error family.
"""

from .mission_client import MissionClient
from .results import (
    BarrierAdded,
    ControlCommand,
    ControlSent,
    MarkerAdded,
    MissionSaved,
    Result,
    RevisionConflict,
    ServerUnavailable,
    SkillAdded,
    SkillRetried,
    Transferred,
)
from .watch import MissionWatch, init_node
from .wire import agent_status_from_msg, agent_statuses_from_msg, library_from_msg

__all__ = [
    "BarrierAdded",
    "ControlCommand",
    "ControlSent",
    "MarkerAdded",
    "MissionClient",
    "MissionSaved",
    "MissionWatch",
    "Result",
    "RevisionConflict",
    "ServerUnavailable",
    "SkillAdded",
    "SkillRetried",
    "Transferred",
    "agent_status_from_msg",
    "agent_statuses_from_msg",
    "init_node",
    "library_from_msg",
]
