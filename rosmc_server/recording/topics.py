"""Channels of the mission journal: topic names, message types and encodings.

The journal records the same graph names the mission server publishes on, so a
recording replays onto the live graph unchanged. These names move to
``rosmc_server/interface.py`` once it exists; import them from this module (or
the package) until then.
"""

from collections.abc import Mapping
from types import MappingProxyType
from typing import Final

MISSION_EVENTS_TOPIC: Final = "/rosmc/mission_events"
"""One ``rosmc/MissionEvent`` per accepted change of the mission."""

MISSION_TOPIC: Final = "/rosmc/mission"
"""Full ``rosmc/Mission`` snapshots: first record of every journal, then periodically."""

ROBOT_REPORTS_TOPIC: Final = "/rosmc/robot_reports"
"""``rosmc/RobotReport`` skill status changes reported by the robots (optional)."""

AGENT_STATES_TOPIC: Final = "/rosmc/agent_states"
"""``rosmc/AgentStates`` aggregated agent state for timelines (optional, low rate)."""

JOURNAL_TOPICS: Final[Mapping[str, str]] = MappingProxyType(
    {
        MISSION_EVENTS_TOPIC: "rosmc/MissionEvent",
        MISSION_TOPIC: "rosmc/Mission",
        ROBOT_REPORTS_TOPIC: "rosmc/RobotReport",
        AGENT_STATES_TOPIC: "rosmc/AgentStates",
    }
)
"""Every journal channel with the ROS message type it carries, in channel-id order."""

PROFILE: Final = "ros1"
MESSAGE_ENCODING: Final = "ros1"
SCHEMA_ENCODING: Final = "ros1msg"
"""MCAP profile and encodings: ROS 1 serialisation with ``.msg`` text schemas."""
