"""What the server's helpers (services, publishers) need from the mission server.

:class:`~rosmc_server.ros.server_node.MissionServer` is a :class:`ServerHost`; the helpers
it builds (:mod:`.operator_services`, :mod:`.whole_mission`, :mod:`.team_sync`,
:mod:`.agent_states`) take one, so they need not import the node that builds them.
"""

from __future__ import annotations

from collections.abc import Callable
from contextlib import AbstractContextManager
from typing import Protocol

from ..conversions.packing import PackedMission
from ..core import Library, Mission, MissionContent, MissionEvent
from .ground_link import GroundLink
from .server_config import ServerConfig


class ServerHost(Protocol):
    """The mission server as its helpers see it: the mission, its lock and its one way in."""

    @property
    def mission(self) -> Mission:
        """The mission (Unavailable once the journal failed)."""

    @property
    def config(self) -> ServerConfig:
        """The server's settings."""

    @property
    def library(self) -> Library:
        """The skill library the mission uses."""

    @property
    def link(self) -> GroundLink:
        """The robot links."""

    @property
    def epoch(self) -> str:
        """The mission's history: new whenever a resume lost history."""

    @property
    def journal_alert(self) -> str:
        """What resuming the journal lost and whether its disk is full ("" if neither)."""

    def locked(self) -> AbstractContextManager[object]:
        """The server lock (re-entrant)."""

    def apply(self, operation: Callable[[Mission], MissionEvent | None]) -> MissionEvent | None:
        """Run ``operation`` on the mission and record the event it returns."""

    def snapshot_msg(self) -> PackedMission:
        """The full mission as a message, stamped now."""

    def drop_snapshot(self) -> None:
        """Let the snapshot's bytes go while a load reads its document."""

    def prepare_snapshot(self, content: MissionContent) -> None:
        """Serialize a mission about to replace this one (a load), outside the lock."""
