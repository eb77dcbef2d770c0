"""The mission of a replay: its revision at the replay's position, and its snapshots.

A replay shows the mission as the recording held it at the position: the revision of the
last change recorded by then, rebuilt from the recording's history (packed, so a seek
serializes only the skills not in the last snapshot built), or the recorded snapshot where
the history has a gap. Free of rospy; :class:`~.replayer.RecordingReplayer` holds its lock
around every call.
"""

from __future__ import annotations

from typing import Any

from .. import interface
from ..conversions.packing import SnapshotPacker
from ..core import NotFound
from ..recording.history import MissionHistory
from ..recording.playback import Playlist


class ReplayMission:
    """The replay's mission (not thread-safe: the replayer serialises calls).

    Attributes:
        current: The revision the replay shows.
        stamp: The mission clock of ``current`` (stamped on its snapshots).
    """

    def __init__(self, history: MissionHistory, playlist: Playlist, position: float) -> None:
        self._history = history
        self._playlist = playlist
        self._built: tuple[int, Any] | None = None  # the last snapshot built, for get_mission
        self._packer = SnapshotPacker()
        self.current = history.revision_at(position).revision
        self.stamp = self.stamp_at(position)

    def move_to(self, position: float) -> Any:
        """Show the mission at ``position`` (s); its snapshot message (None if none)."""
        self.current = self._history.revision_at(position).revision
        self.stamp = self.stamp_at(position)
        return self.message(self.current, position)

    def message(self, revision: int, position: float | None = None) -> Any:
        """The mission at ``revision`` as a message; where the history lacks it, the snapshot
        recorded by ``position`` (None without a position, or if none was recorded)."""
        if self._built is not None and self._built[0] == revision:
            return self._built[1]
        try:
            state = self._history.at_revision(revision)
        except NotFound:  # a gap in the recording: its recorded snapshot follows
            if position is None:
                return None
            recorded = self._playlist.latest(interface.MISSION_TOPIC, position)
            return None if recorded is None else recorded.message
        msg = self._packer.pack(state.content(), revision, self.stamp)
        self._built = (revision, msg)
        return msg

    def stamp_at(self, position: float) -> float:
        """The mission clock of the last change recorded at or before ``position``."""
        records = [
            self._playlist.latest(topic, position)
            for topic in (interface.EVENTS_TOPIC, interface.MISSION_TOPIC)
        ]
        latest = max((r for r in records if r is not None), key=lambda r: r.log_time, default=None)
        return 0.0 if latest is None else float(latest.field("stamp").to_sec())
