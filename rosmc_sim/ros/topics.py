"""Graph names of the simulator and the simulated robots' controllers."""

from __future__ import annotations

# The science state and world markers are journaled by the server, and the server checks
# skill targets against the site: their names live in the shared table.
from rosmc_server.interface import SCIENCE_TOPIC, SITE_TOPIC, WORLD_TOPIC

__all__ = ["SCIENCE_TOPIC", "SIM_NODE", "SITE_TOPIC", "WORLD_TOPIC"]

SIM_NODE = "/rosmc/sim"


def skill_run_topic(robot: str) -> str:
    """rosmc/SkillRun requests to a robot's controllers."""
    return f"/{robot}/sim/skill_run"


def skill_run_status_topic(robot: str) -> str:
    """rosmc/SkillRunStatus from a robot's controllers."""
    return f"/{robot}/sim/skill_run_status"


def blackout_topic(agent: str) -> str:
    """std_msgs/Bool: true while the agent is out of radio coverage."""
    return f"/{agent}/link/blackout"


def odom_topic(robot: str) -> str:
    """nav_msgs/Odometry of a robot."""
    return f"/{robot}/odom"
