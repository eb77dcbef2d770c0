"""The one boundary between the ``rosmc`` messages and the core objects.

Nothing else converts: the server, the client, the recording, the executor
adapter and the simulator all go through these functions. They need the
generated messages and genpy only, never rospy, so the journal reader and
replay tools use them without a ROS graph.

Layers: :mod:`rosmc_server.core` < this package < :mod:`rosmc_server.recording`
and the ROS adapters (``rosmc_server.ros``, ``rosmc_server.executor.ros``) <
the client (``rosmc_server.ros.client``) < the CLI and GUIs.

Modules:

* :mod:`.values`: times, poses and named parameter values;
* :mod:`.mission`: skills, barriers, task markers, mission snapshots and events;
* :mod:`.packing`: mission snapshots as wire bytes, built incrementally and serialized once
  (import it from the module);
* :mod:`.library`: the skill library, both ways;
* :mod:`.agents`: agent states (``rosmc/AgentStates``) as core ``AgentStatus``;
* :mod:`.policy`: the lost-link policy <-> ``rosmc/SetLostLinkPolicy`` request fields, and
  the policy a robot reports in force <-> ``rosmc/LostLinkPolicy``;
* :mod:`.site`: the site map (``rosmc/SiteMap``) the server checks skill targets against;
* :mod:`.robot_link`: the robot link's protocol (commands, acks, reports, barrier
  signals, snapshots); import it from the module.

``x_to_msg`` builds a message from a core object and ``x_from_msg`` the object
back; malformed input raises :class:`~rosmc_server.core.InvalidRequest` (or
ValueError in :mod:`.robot_link`, for the executor). Round trips are exact.
"""

from .agents import agent_status_from_msg, agent_statuses_from_msg
from .library import library_from_msg, library_to_msg, parameter_spec_to_msg
from .mission import (
    barrier_from_msg,
    barrier_to_msg,
    event_from_msg,
    event_to_msg,
    marker_from_msg,
    marker_to_msg,
    mission_from_msg,
    mission_to_msg,
    moves_from_msgs,
    moves_to_msgs,
    skill_from_msg,
    skill_to_msg,
)
from .policy import (
    policy_from_request,
    policy_in_force_from_msg,
    policy_in_force_to_msg,
    policy_to_request,
)
from .site import site_from_msg, site_in_force_from_msg, site_in_force_to_msg, site_to_msg
from .values import (
    MAX_JSON_NESTING,
    param_from_msg,
    param_to_msg,
    params_from_msgs,
    pose_from_msg,
    pose_to_msg,
    time_to_msg,
    value_type,
)

__all__ = [
    "MAX_JSON_NESTING",
    "agent_status_from_msg",
    "agent_statuses_from_msg",
    "barrier_from_msg",
    "barrier_to_msg",
    "event_from_msg",
    "event_to_msg",
    "library_from_msg",
    "library_to_msg",
    "marker_from_msg",
    "marker_to_msg",
    "mission_from_msg",
    "mission_to_msg",
    "moves_from_msgs",
    "moves_to_msgs",
    "param_from_msg",
    "param_to_msg",
    "parameter_spec_to_msg",
    "params_from_msgs",
    "policy_from_request",
    "policy_in_force_from_msg",
    "policy_in_force_to_msg",
    "policy_to_request",
    "pose_from_msg",
    "pose_to_msg",
    "site_from_msg",
    "site_in_force_from_msg",
    "site_in_force_to_msg",
    "site_to_msg",
    "skill_from_msg",
    "skill_to_msg",
    "time_to_msg",
    "value_type",
]
