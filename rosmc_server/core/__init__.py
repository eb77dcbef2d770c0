"""The mission core: the ROSMC mission model and its rules, in pure Python.

No rospy, genpy, generated messages, Qt or pybullet are imported here;
:mod:`rosmc_server.conversions` translates between this and the messages.

The core is in subpackages by concern, each importing only from those before it
(:data:`SUBPACKAGE_ORDER`; ``tests/unit/test_layering.py`` checks it):

* :mod:`.world`: orientation math, area polygons, the site map;
* :mod:`.documents`: reading YAML documents, durable file writes;
* :mod:`.skills`: the skill library, parameter types, lost-link policies;
* :mod:`.model`: skills, barriers, markers, task order, the state, changes;
* :mod:`.views`: the words, marks, colours and drawing primitives every view shares;
* :mod:`.robots`: the robot link, the radio, commands that wait, robots' live status;
* :mod:`.live`: events applied to a state, a client's live mirror;
* :mod:`.rules`: the mission object and every operator rule;
* :mod:`.files`: mission files read and written.

:mod:`.errors`, :mod:`.validation` and :mod:`.collector` are below them all.
"""

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
from .files.persistence import (
    dump_mission,
    load_mission,
    mission_to_dict,
    parse_mission,
    save_mission,
)
from .model.changes import Change, EventKind, MissionEvent, PlacedSkill
from .model.model import Barrier, Resolution, SkillInstance, SkillStatus, TaskMarker, Transfer
from .model.state import MissionContent, MissionState
from .robots.agent_status import AgentStatus
from .rules.mission import Mission, random_ids
from .skills.library import (
    AgentKind,
    AgentSpec,
    Library,
    ParameterSpec,
    SkillSpec,
    load_library,
)
from .skills.params import MarkerType, ParamType, Pose, Value
from .skills.policy import LostLinkKind, LostLinkPolicy, LostLinkTrigger, PolicyInForce

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
    "PolicyInForce",
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

# The subpackages in order: each imports only from those before it and the foundation.
SUBPACKAGE_ORDER = (
    "world",
    "documents",
    "skills",
    "model",
    "views",
    "robots",
    "live",
    "rules",
    "files",
)
FOUNDATION = ("errors", "validation", "collector")
