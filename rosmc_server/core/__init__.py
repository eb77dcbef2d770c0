"""The mission core: the ROSMC mission model and its rules, in pure Python.

No rospy, genpy, generated messages, Qt or pybullet are imported here;
:mod:`rosmc_server.conversions` translates between this and the messages.
"""

from .agent_status import AgentStatus
from .changes import Change, EventKind, MissionEvent, PlacedSkill
from .errors import (
    InvalidRequest,
    LibraryError,
    MissionFileError,
    NotFound,
    NotPermitted,
    RosmcError,
    RuleViolation,
    SkillSetupError,
    StaleRevision,
    StorageFull,
    Unavailable,
)
from .library import (
    AgentKind,
    AgentSpec,
    Library,
    ParameterSpec,
    SkillSpec,
    load_library,
)
from .mission import Mission, random_ids
from .model import Barrier, Resolution, SkillInstance, SkillStatus, TaskMarker, Transfer
from .params import MarkerType, ParamType, Pose, Value
from .persistence import (
    dump_mission,
    load_mission,
    mission_to_dict,
    parse_mission,
    save_mission,
)
from .policy import LostLinkKind, LostLinkPolicy, LostLinkTrigger
from .state import MissionContent, MissionState

__all__ = [
    "AgentKind",
    "AgentSpec",
    "AgentStatus",
    "Barrier",
    "Change",
    "EventKind",
    "InvalidRequest",
    "Library",
    "LibraryError",
    "LostLinkKind",
    "LostLinkPolicy",
    "LostLinkTrigger",
    "MarkerType",
    "Mission",
    "MissionContent",
    "MissionEvent",
    "MissionFileError",
    "MissionState",
    "NotFound",
    "NotPermitted",
    "ParamType",
    "ParameterSpec",
    "PlacedSkill",
    "Pose",
    "Resolution",
    "RosmcError",
    "RuleViolation",
    "SkillInstance",
    "SkillSetupError",
    "SkillSpec",
    "SkillStatus",
    "StaleRevision",
    "StorageFull",
    "TaskMarker",
    "Transfer",
    "Unavailable",
    "Value",
    "dump_mission",
    "load_library",
    "load_mission",
    "mission_to_dict",
    "parse_mission",
    "random_ids",
    "save_mission",
]
