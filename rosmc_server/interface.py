"""Every ROS graph name the mission server, its clients and the robots share, in one place.

The mission server, the robot executors, the GUIs, the simulator, the CLI and the
journal (whose channels are these topics) import their topic, service and TF frame
names from here, so a rename happens once. Names are plain strings; nothing here
imports rospy. Names that only one component uses live next to it (the simulator's
in ``rosmc_sim/ros/topics.py``, the marker node's in ``rosmc_rviz_markers/topics.py``),
and every node reads its private parameters (``~name``) once, into its config, listing
them in its docstring.
"""

from __future__ import annotations

from dataclasses import dataclass

NAMESPACE = "/rosmc"
SERVER_NODE = f"{NAMESPACE}/mission_server"

# Published by the mission server, and journaled (the journal's channels carry these names).
MISSION_TOPIC = f"{NAMESPACE}/mission"  # rosmc/Mission, latched snapshot
EVENTS_TOPIC = f"{NAMESPACE}/mission_events"  # rosmc/MissionEvent, one per change
AGENT_STATES_TOPIC = f"{NAMESPACE}/agent_states"  # rosmc/AgentStates, steady rate
# Journaled only (the robots' skill status reports, for the audit trail); a replay publishes it.
ROBOT_REPORTS_TOPIC = f"{NAMESPACE}/robot_reports"  # rosmc/RobotReport
# Journaled only: each command for a robot, when asked and when delivered (or cancelled).
ROBOT_COMMANDS_TOPIC = f"{NAMESPACE}/robot_commands"  # rosmc/CommandRecord
# Journaled only: the skill library the server ran with (a replay serves it as get_library).
LIBRARY_TOPIC = f"{NAMESPACE}/library"  # rosmc/Library
# Published by robots (or the simulator), one topic per agent.
TELEMETRY_TOPIC = "/{agent}/telemetry"  # rosmc/Telemetry
# Published by the robots or the simulator, and journaled by the server (low rate) so that a
# recording shows where the robots were, the site and the score.
TF_TOPIC = "/tf"  # tf2_msgs/TFMessage: map -> <agent>/base_link
SCIENCE_TOPIC = f"{NAMESPACE}/sim/science"  # rosmc/ScienceState, latched: regions and score
WORLD_TOPIC = f"{NAMESPACE}/sim/world"  # visualization_msgs/MarkerArray, latched: the site
# Published latched by the site's map provider (the simulator, or a real site's mapping); the
# mission server checks skill targets against the newest one.
SITE_TOPIC = f"{NAMESPACE}/site"  # rosmc/SiteMap
# Published latched and journaled by the mission server: the map in force, who sent it, when.
SITE_IN_FORCE_TOPIC = f"{NAMESPACE}/site_in_force"  # rosmc/SiteInForce
# rosmc/CoverageGrid, latched: the simulator's radio model (access point, deployed Wi-Fi
# boxes, obstacles); the server's coverage estimate and rviz's coverage layer read it.
COVERAGE_MODEL_TOPIC = f"{NAMESPACE}/sim/coverage"
# visualization_msgs/MarkerArray: radio coverage shaded by signal, last-link marks.
COVERAGE_MARKERS_TOPIC = f"{NAMESPACE}/coverage"

# A replay (``rosmc replay``) is steered through one service and says where it is.
REPLAY_CONTROL_SERVICE = f"{NAMESPACE}/replay/control"  # rosmc/ReplayControl
REPLAY_STATE_TOPIC = f"{NAMESPACE}/replay/state"  # rosmc/ReplayState, latched

# Operator services of the mission server: name -> srv type name.
SERVICES = {
    "add_skill": "AddSkill",
    "edit_skill": "EditSkill",
    "delete_skills": "DeleteSkills",
    "reorder_skills": "ReorderSkills",
    "synchronize": "Synchronize",
    "synchronize_team": "SynchronizeTeam",
    "unsynchronize": "Unsynchronize",
    "control": "Control",
    "set_lost_link_policy": "SetLostLinkPolicy",
    "retry_skill": "RetrySkill",
    "skip_skill": "SkipSkill",
    "add_barrier": "AddBarrier",
    "delete_barrier": "DeleteBarrier",
    "add_task_marker": "AddTaskMarker",
    "move_task_marker": "MoveTaskMarker",
    "rename_task_marker": "RenameTaskMarker",
    "delete_task_marker": "DeleteTaskMarker",
    "undo_edit": "UndoEdit",
    "new_mission": "NewMission",
    "save_mission": "SaveMission",
    "load_mission": "LoadMission",
    "get_mission": "GetMission",
    "get_library": "GetLibrary",
}


def service_name(operation: str, prefix: str = "") -> str:
    """Full name of an operator service, e.g. ``/rosmc/add_skill`` (``/replay/rosmc/...``)."""
    if operation not in SERVICES:
        raise KeyError(f"unknown operator service {operation!r}")
    return prefixed(f"{NAMESPACE}/{operation}", prefix)


def prefixed(name: str, prefix: str) -> str:
    """``name`` behind a namespace prefix such as ``/replay`` ("" leaves it as it is).

    A replay (``rosmc replay --prefix /replay``) publishes the live names behind a
    prefix; clients that follow it put the same prefix before every name they use.
    """
    base = prefix.strip().rstrip("/")
    if base and not base.startswith("/"):
        base = "/" + base
    return base + name


# TF frames: every pose on the graph is in the map frame; each agent's body frame hangs
# below it (the simulator, or a real robot's localisation, publishes map -> base_link).
MAP_FRAME = "map"


def base_link(agent: str) -> str:
    """The body frame of ``agent`` on TF, e.g. ``drone/base_link``."""
    return f"{agent}/base_link"


# Which skills and task markers an operator has selected, shared by the command GUI and
# rviz so that selecting in one highlights in the other (rosmc/Selection, latched).
SELECTION_TOPIC = f"{NAMESPACE}/selection"


# The operator station's two windows open each other and show the same source:
# std_msgs/Empty requests to bring rviz / the command window to the front, and the prefix
# rviz shows (std_msgs/String, latched: "" the live mission, "/replay" a replay).
STATION_NAMESPACE = f"{NAMESPACE}/station"
SHOW_3D_TOPIC = f"{STATION_NAMESPACE}/show_3d"
SHOW_COMMAND_TOPIC = f"{STATION_NAMESPACE}/show_command"
VIEW_SOURCE_TOPIC = f"{STATION_NAMESPACE}/view_source"
RVIZ_NODE = "/rviz_operator"  # the operator's rviz (launch/rviz.launch)

# Robot-to-robot barrier coordination (never through the ground station).
BARRIER_TOPIC = f"{NAMESPACE}/barriers"  # rosmc/BarrierSignal, for observers
# Parameter namespace of the radio side channel: <name> -> "host:port" (ros/radio.py).
RADIO_DIRECTORY = f"{NAMESPACE}/radio"


@dataclass(frozen=True)
class LinkTopics:
    """The five topics of one agent's robot link.

    The ground station uses the names under ``/rosmc/link/<agent>``. A robot's
    executor uses the same names, unless a link emulator relays between the
    ground names and robot-side names (``/<agent>/link``) to add latency,
    loss and blackouts; then the executor is started with the robot prefix.
    """

    command: str  # rosmc/RobotCommand, ground -> robot
    ack: str  # rosmc/RobotAck, robot -> ground
    report: str  # rosmc/RobotReport, robot -> ground
    report_ack: str  # rosmc/ReportAck, ground -> robot
    snapshot: str  # rosmc/ExecutorSnapshot, robot -> ground

    @classmethod
    def under(cls, prefix: str) -> LinkTopics:
        """The link topics below ``prefix``."""
        base = prefix.rstrip("/")
        return cls(
            f"{base}/command",
            f"{base}/ack",
            f"{base}/report",
            f"{base}/report_ack",
            f"{base}/snapshot",
        )


def ground_link(agent: str) -> LinkTopics:
    """The ground station's side of ``agent``'s robot link."""
    return LinkTopics.under(f"{NAMESPACE}/link/{agent}")


def robot_link(agent: str) -> LinkTopics:
    """The robot's side of ``agent``'s link when an emulator relays it."""
    return LinkTopics.under(f"/{agent}/link")
