"""Graph names of the simulator and the simulated robots' controllers."""

from __future__ import annotations

SIM_NODE = "/rosmc/sim"
SCIENCE_TOPIC = "/rosmc/sim/science"  # rosmc/ScienceState, latched
WORLD_TOPIC = "/rosmc/sim/world"  # visualization_msgs/MarkerArray, latched


def task_topic(robot: str) -> str:
    """rosmc/RobotTask requests to a robot's controllers."""
    return f"/{robot}/sim/task"


def task_status_topic(robot: str) -> str:
    """rosmc/RobotTaskStatus from a robot's controllers."""
    return f"/{robot}/sim/task_status"


def blackout_topic(agent: str) -> str:
    """std_msgs/Bool: true while the agent is out of radio coverage."""
    return f"/{agent}/link/blackout"


def odom_topic(robot: str) -> str:
    """nav_msgs/Odometry of a robot."""
    return f"/{robot}/odom"
