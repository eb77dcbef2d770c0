"""The executor's private parameters, read once at start (see :mod:`.node` for each)."""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path

import rospy

from rosmc_server.common.ros.station import launch_path

from ..core.pacing import IDLE_PERIOD

DEFAULT_SKILLS = "rosmc_server.executor.basic_skills:skill_types"


def default_state_file(agent: str) -> Path:
    """``$ROS_HOME/rosmc/<agent>_executor.json``."""
    ros_home = os.environ.get("ROS_HOME") or os.path.join(os.path.expanduser("~"), ".ros")
    return Path(ros_home) / "rosmc" / f"{agent}_executor.json"


@dataclass(frozen=True)
class ExecutorConfig:
    """The executor's private parameters (``~name``), read once at start."""

    agent: str
    skills: str = DEFAULT_SKILLS
    library: str = ""
    pose_source: str = ""
    state_file: Path | None = None
    robot_side: bool = False
    tick_rate: float = 50.0
    snapshot_period: float = 1.0
    idle_snapshot_period: float = IDLE_PERIOD
    report_retry: float = 0.5
    radio_key: str = ""  # "" = $ROS_HOME/rosmc/radio.key, made if missing

    @classmethod
    def from_params(cls) -> ExecutorConfig:
        """Read every private parameter, then delete them from the parameter server.

        Left there, they would configure the next executor started under the same name:
        a ``~robot_side`` left by a run behind the link emulator made a later direct
        executor talk on the wrong topics and never link.
        """
        agent = str(rospy.get_param("~agent", ""))
        default_state = str(default_state_file(agent)) if agent else ""
        state = str(rospy.get_param("~state_file", default_state))
        radio_key = str(rospy.get_param("~radio_key", ""))
        config = cls(
            agent=agent,
            skills=str(rospy.get_param("~skills", DEFAULT_SKILLS)),
            library=str(rospy.get_param("~library", "")),
            pose_source=str(rospy.get_param("~pose_source", "")),
            state_file=launch_path(state) if state else None,
            robot_side=bool(rospy.get_param("~robot_side", False)),
            tick_rate=float(rospy.get_param("~tick_rate", 50.0)),
            snapshot_period=float(rospy.get_param("~snapshot_period", 1.0)),
            idle_snapshot_period=float(rospy.get_param("~idle_snapshot_period", IDLE_PERIOD)),
            report_retry=float(rospy.get_param("~report_retry", 0.5)),
            radio_key=str(launch_path(radio_key)) if radio_key else "",
        )
        for name in PRIVATE_PARAMS:
            if rospy.has_param(f"~{name}"):
                rospy.delete_param(f"~{name}")
        return config


PRIVATE_PARAMS = (
    "agent",
    "skills",
    "library",
    "pose_source",
    "state_file",
    "robot_side",
    "tick_rate",
    "snapshot_period",
    "idle_snapshot_period",
    "report_retry",
    "radio_key",
    "cwd",
)
