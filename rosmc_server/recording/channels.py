"""Channels of the mission journal: which graph topics it records, their types and encodings.

The journal records the topics the mission server publishes, under the same names
(:mod:`rosmc_server.interface` holds them), so a recording replays onto the live
graph unchanged.
"""

from collections.abc import Mapping
from types import MappingProxyType
from typing import Final

from rosmc_server.interface import (
    AGENT_STATES_TOPIC,
    EVENTS_TOPIC,
    LIBRARY_TOPIC,
    MISSION_TOPIC,
    ROBOT_COMMANDS_TOPIC,
    ROBOT_REPORTS_TOPIC,
    SCIENCE_TOPIC,
    SITE_IN_FORCE_TOPIC,
    TF_TOPIC,
    WORLD_TOPIC,
)

JOURNAL_TOPICS: Final[Mapping[str, str]] = MappingProxyType(
    {
        EVENTS_TOPIC: "rosmc/MissionEvent",  # one per accepted change of the mission
        MISSION_TOPIC: "rosmc/Mission",  # full snapshots: the first record, then periodically
        ROBOT_REPORTS_TOPIC: "rosmc/RobotReport",  # skill status reports of the robots
        AGENT_STATES_TOPIC: "rosmc/AgentStates",  # on change, at most 2 Hz
        TF_TOPIC: "tf2_msgs/TFMessage",  # map -> <robot>/base_link, 2 Hz
        SCIENCE_TOPIC: "rosmc/ScienceState",  # the score and discovered regions, on change
        WORLD_TOPIC: "visualization_msgs/MarkerArray",  # the simulated site, on change
        # Added later, so last: older journals lack it and keep their channel ids.
        ROBOT_COMMANDS_TOPIC: "rosmc/CommandRecord",  # commands for robots: asked, delivered
        SITE_IN_FORCE_TOPIC: "rosmc/SiteInForce",  # the site map in force, its sender, when
        LIBRARY_TOPIC: "rosmc/Library",  # the library the server ran with: once per part file
    }
)
"""Every journal channel with the ROS message type it carries, in channel-id order."""

TELEMETRY_TOPICS: Final = (
    ROBOT_REPORTS_TOPIC,
    AGENT_STATES_TOPIC,
    TF_TOPIC,
    SCIENCE_TOPIC,
    WORLD_TOPIC,
    ROBOT_COMMANDS_TOPIC,
    SITE_IN_FORCE_TOPIC,
)
"""Channels of what the robots and the site did: written, never fsynced on their own."""

LATCHED_TOPICS: Final = (
    MISSION_TOPIC,
    SCIENCE_TOPIC,
    WORLD_TOPIC,
    SITE_IN_FORCE_TOPIC,
    LIBRARY_TOPIC,
)
"""Channels whose live publishers latch them (a replay and a converted bag latch them too)."""

LIBRARY: Final = "rosmc-journal/1"
"""The library field of a journal's MCAP header: a file with it was written by JournalWriter."""

PROFILE: Final = "ros1"
MESSAGE_ENCODING: Final = "ros1"
SCHEMA_ENCODING: Final = "ros1msg"
"""MCAP profile and encodings: ROS 1 serialisation with ``.msg`` text schemas."""
