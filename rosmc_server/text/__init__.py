"""Plain-text and JSON views of a mission, its library and its events.

Pure functions over core objects (no rospy): the ``rosmc`` command line, the
scripted demo and tests share them. :mod:`.plain` renders text for people
(each robot's task, status marks, tags); :mod:`.data` returns plain data
with stable keys for ``--json`` output.
"""

from .data import (
    agent_status_to_json,
    event_to_json,
    library_to_json,
    marker_to_json,
    mission_to_json,
    site_to_json,
    skill_to_json,
)
from .plain import (
    format_agent_status,
    format_event,
    format_library,
    format_markers,
    format_params,
    format_tasks,
    format_value,
)

__all__ = [
    "agent_status_to_json",
    "event_to_json",
    "format_agent_status",
    "format_event",
    "format_library",
    "format_markers",
    "format_params",
    "format_tasks",
    "format_value",
    "library_to_json",
    "marker_to_json",
    "mission_to_json",
    "site_to_json",
    "skill_to_json",
]
