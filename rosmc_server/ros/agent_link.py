"""What the ground tracks about each robot link, and what it needs of the mission server."""

from __future__ import annotations

from collections.abc import Callable
from contextlib import AbstractContextManager
from dataclasses import dataclass, field
from typing import Protocol

import rosmc.msg as wire
import rospy

from ..common.ros.radio import TopicListener
from ..core import Barrier, Mission, MissionEvent
from ..core.robots.link import InboundSequence, Outbox

Operation = Callable[[Mission], MissionEvent | None]


class LinkHost(Protocol):
    """What the ground link needs from the mission server."""

    @property
    def mission(self) -> Mission:
        """The mission (Unavailable once the journal failed)."""

    def apply(self, operation: Operation) -> MissionEvent | None:
        """Run a mission operation and record its event; the lock is held by the caller."""

    def locked(self) -> AbstractContextManager[object]:
        """The server lock, as a context manager."""

    def record_report(self, msg: wire.RobotReport) -> None:
        """Journal a robot report for the audit trail."""

    def record_command(self, msg: wire.CommandRecord) -> None:
        """Journal a command asked, delivered or cancelled."""


@dataclass
class AgentLink:
    """Everything the ground tracks about one agent's link."""

    agent: str
    outbox: Outbox[wire.RobotCommand]
    command_pub: rospy.Publisher
    report_ack_pub: rospy.Publisher
    reports: InboundSequence | None = None  # None until the robot's numbering is known
    snapshot: wire.ExecutorSnapshot | None = None
    asked_after: float | None = None  # the silence the last policy sent acts after
    robot_hash: str = ""
    mismatch: bool = False
    barriers_sent: tuple[Barrier, ...] = ()
    newest_stamp: float = 0.0  # robot clock of the newest message heard from it
    want_full: bool = False  # ask the robot for a snapshot with its whole queue
    full_asked: float = float("-inf")  # when the ground last asked for one on a digest
    last_error: str = ""
    listeners: list[TopicListener] = field(default_factory=list)
