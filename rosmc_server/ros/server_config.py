"""The mission server's settings: its private parameters, read once at start.

Parameters: see :mod:`rosmc_server.ros.server_node`.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import rospy

from ..common.ros import station
from ..core.rules.operators import OperatorAllowList
from ..recording import JournalOptions

PACKAGE_ROOT = Path(__file__).resolve().parents[2]
DEFAULT_LIBRARY = PACKAGE_ROOT / "rosmc_server" / "config" / "mars_team.yaml"
DEFAULT_JOURNAL_DIR = PACKAGE_ROOT / "bags"
DEFAULT_MISSION_DIR = PACKAGE_ROOT / "missions"


@dataclass(frozen=True)
class ServerConfig:
    """The server's settings, read once at start."""

    library: Path = DEFAULT_LIBRARY
    journal: Path | None = None
    journal_dir: Path = DEFAULT_JOURNAL_DIR
    resume: bool = False
    link_timeout: float = 3.0
    agent_state_rate: float = 2.0
    fsync: bool = True
    mission_dir: Path = DEFAULT_MISSION_DIR
    snapshot_every: int = JournalOptions.snapshot_every
    journal_reserve: int = JournalOptions.reserve_bytes
    operators: OperatorAllowList = field(default_factory=OperatorAllowList)
    broadcast_snapshots: bool = False
    radio_key: str = ""  # "" = $ROS_HOME/rosmc/radio.key, made if missing

    @classmethod
    def from_params(cls) -> ServerConfig:
        """Read the private parameters (``~name``).

        ``~journal`` and ``~resume`` are deleted once read: left on the parameter
        server (as ``rosrun ... _resume:=true`` leaves them), they would make a
        later, plain start resume an old journal.
        """
        journal = str(rospy.get_param("~journal", ""))
        resume = bool(rospy.get_param("~resume", False))
        for once in ("~journal", "~resume"):
            if rospy.has_param(once):
                rospy.delete_param(once)
        radio_key = str(rospy.get_param("~radio_key", ""))
        previous = station.previous_journal()
        if previous is not None:  # restarted by roslaunch: go on where the last server was
            journal, resume = str(previous), True
        return cls(
            library=station.launch_path(str(rospy.get_param("~library", str(DEFAULT_LIBRARY)))),
            journal=station.launch_path(journal) if journal else None,
            journal_dir=station.launch_path(
                str(rospy.get_param("~journal_dir", str(DEFAULT_JOURNAL_DIR)))
            ),
            resume=resume,
            link_timeout=float(rospy.get_param("~link_timeout", 3.0)),
            agent_state_rate=float(rospy.get_param("~agent_state_rate", 2.0)),
            fsync=bool(rospy.get_param("~fsync", True)),
            mission_dir=station.launch_path(
                str(rospy.get_param("~mission_dir", str(DEFAULT_MISSION_DIR)))
            ),
            snapshot_every=max(1, int(rospy.get_param("~snapshot_every", cls.snapshot_every))),
            journal_reserve=max(0, int(rospy.get_param("~journal_reserve", cls.journal_reserve))),
            operators=OperatorAllowList.of(rospy.get_param("~operators", [])),
            broadcast_snapshots=bool(rospy.get_param("~broadcast_snapshots", False)),
            radio_key=str(station.launch_path(radio_key)) if radio_key else "",
        )
