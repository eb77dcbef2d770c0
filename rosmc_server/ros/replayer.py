"""Republishing a recorded mission onto the ROS graph, as the mission server published it.

:class:`RecordingReplayer` plays a journal back at a chosen rate: what the
server recorded at log time ``t`` is published ``(t - start) / rate`` seconds
after the replay began, so rviz, the command GUI and ``rosmc watch`` show the
mission evolving. It refuses to play onto names another node publishes on
(a live mission server); a topic prefix moves the replay out of their way.

Publishes (each name behind ``prefix``):
    ``/rosmc/mission`` (rosmc/Mission, latched): the mission at the start time, then the
    mission after every burst of events (rebuilt from the recording, as the server
    coalesces its snapshots).
    ``/rosmc/mission_events`` (rosmc/MissionEvent): every recorded event after the start.
    ``/rosmc/agent_states`` (rosmc/AgentStates): as recorded (the latest one at once).
    ``/rosmc/robot_reports`` (rosmc/RobotReport): as recorded.
    ``/tf`` (tf2_msgs/TFMessage): the robots' recorded transforms (``<prefix>/tf`` with a
    prefix: ``roslaunch rosmc rviz.launch ns:=/replay`` remaps rviz's ``/tf`` to it).
    ``/rosmc/sim/science`` (rosmc/ScienceState, latched), ``/rosmc/sim/world``
    (visualization_msgs/MarkerArray, latched): the site and the score, as recorded.

Services (behind ``prefix``):
    ``/rosmc/get_mission`` (rosmc/GetMission): the mission as replayed so far, so clients that
    start from it (``rosmc watch``, the GUIs) follow the replay as they follow a live server.

The replayer serves clients and is driven by ``rosmc replay``; it ranks with the client
(``rosmc_server.ros.client``) in the layers, above the server's adapters. Its callers need
no rospy: :meth:`RecordingReplayer.run` makes the process a node itself and hands each
event over as a core :class:`~rosmc_server.core.MissionEvent`.
"""

from __future__ import annotations

import logging
import os
import threading
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

import rosgraph
import rosmc.msg as wire
import rosmc.srv as wire_srv
import rospy
from tf2_msgs.msg import TFMessage
from visualization_msgs.msg import MarkerArray

from .. import interface
from ..conversions import event_from_msg, mission_to_msg
from ..core import EventKind, InvalidRequest, MissionEvent, NotFound, RosmcError
from ..recording import JournalRecord
from ..recording.history import MissionHistory
from .client import ServerUnavailable, init_node

_log = logging.getLogger(__name__)

QUIET = 0.05
"""Seconds without events after which the rebuilt snapshot is published (as the server)."""
MAX_DELAY = 0.25
"""Longest a burst of events goes without a new snapshot."""
WARM_UP = 0.5
"""Seconds for subscribers to connect before the first message."""
LINGER = 1.0
"""Seconds the last messages get to reach their subscribers before the node leaves."""

GET_MISSION = interface.service_name("get_mission")

TYPES: dict[str, Any] = {
    interface.MISSION_TOPIC: wire.Mission,
    interface.EVENTS_TOPIC: wire.MissionEvent,
    interface.AGENT_STATES_TOPIC: wire.AgentStates,
    interface.ROBOT_REPORTS_TOPIC: wire.RobotReport,
    interface.TF_TOPIC: TFMessage,
    interface.SCIENCE_TOPIC: wire.ScienceState,
    interface.WORLD_TOPIC: MarkerArray,
}

LATCHED = (interface.MISSION_TOPIC, interface.SCIENCE_TOPIC, interface.WORLD_TOPIC)
"""Latched as their publishers latch them: a late rviz still gets the site and the score."""

CURRENT_AT_START = (
    interface.AGENT_STATES_TOPIC,
    interface.TF_TOPIC,
    interface.SCIENCE_TOPIC,
    interface.WORLD_TOPIC,
)
"""Topics whose newest message before the start time is published at once."""


EventCallback = Callable[[int, MissionEvent | None, float], None]
"""Called with each replayed event: its revision, the event (None if it does not decode)
and its time in the recording (s)."""


class ReplayRefused(RosmcError):
    """Another node publishes on the names the replay would use."""


@dataclass(frozen=True)
class ReplayConfig:
    """How to play a recording back.

    Attributes:
        rate: Speed-up: 2.0 plays twice as fast as recorded.
        start: Seconds since the recording started to begin at.
        prefix: Put before every topic name ("" = the live names, e.g. ``/replay``).
    """

    rate: float = 1.0
    start: float = 0.0
    prefix: str = ""

    def topic(self, name: str) -> str:
        """A recorded topic's name in this replay."""
        prefix = self.prefix.strip().rstrip("/")
        if prefix and not prefix.startswith("/"):
            prefix = "/" + prefix
        return prefix + name


def taken_names(names: Sequence[str], caller_id: str = "/rosmc_replay") -> dict[str, list[str]]:
    """The nodes publishing each of the topics, or serving each of the services, in ``names``.

    Names nobody uses are left out.

    Raises:
        ServerUnavailable: The ROS master does not answer.
    """
    try:
        publishers, _, services = rosgraph.Master(caller_id).getSystemState()
    except (OSError, rosgraph.MasterException) as err:
        raise ServerUnavailable(
            f"no ROS master answers at {rosgraph.get_master_uri()} ({err}); start roscore first"
        ) from err
    wanted = set(names)
    return {
        name: sorted(nodes) for name, nodes in [*publishers, *services] if name in wanted and nodes
    }


class RecordingReplayer:
    """Plays one recording onto the graph with :meth:`run`.

    Args:
        history: The recording's history (rebuilds the snapshots).
        records: The recording's records (:attr:`JournalResult.records`).
        config: Rate, start time and topic prefix.
        on_event: Called with each event as it is published (see :data:`EventCallback`).
    """

    def __init__(
        self,
        history: MissionHistory,
        records: Sequence[JournalRecord],
        config: ReplayConfig,
        on_event: EventCallback | None = None,
    ) -> None:
        if not config.rate > 0:
            raise InvalidRequest(f"the rate must be a positive number, got {config.rate}")
        if not 0 <= config.start <= history.duration:
            raise InvalidRequest(
                f"the start must be between 0 and {history.duration:.2f} s (the recording's "
                f"length), got {config.start}"
            )
        self._history = history
        self._config = config
        self._on_event = on_event
        start_ns = history.start + round(config.start * 1e9)
        self._before = [r for r in records if r.log_time <= start_ns]
        self._records = sorted((r for r in records if r.log_time > start_ns), key=_log_time)
        self._stop = threading.Event()
        self._publishers: dict[str, rospy.Publisher] = {}
        self._revision = -1  # of the last snapshot published
        self._latest = -1  # of the last event published
        events = [r.message for r in self._before if r.topic == interface.EVENTS_TOPIC]
        self._stamp = events[-1].stamp.to_sec() if events else 0.0  # mission clock of _latest
        self._snapshot: Any = None  # the last snapshot published, for get_mission

    def check_names(self) -> None:
        """Refuse to play if any node publishes the replay's topics or serves its service.

        Raises:
            ReplayRefused: Another node uses one of the names (the message names it).
            ServerUnavailable: The ROS master does not answer.
        """
        names = [self._config.topic(topic) for topic in (*TYPES, GET_MISSION)]
        caller = rospy.get_name() if rospy.core.is_initialized() else "/rosmc_replay"
        taken = taken_names(names, caller)
        if taken:
            held = "; ".join(f"{name} by {', '.join(nodes)}" for name, nodes in taken.items())
            raise ReplayRefused(
                f"these names are in use already: {held}. Stop the live mission server, or "
                "replay under a prefix (--prefix /replay)"
            )

    def stop(self) -> None:
        """End :meth:`run` early (thread-safe)."""
        self._stop.set()

    def run(self) -> int:
        """Check the names, publish everything on time and return the last revision shown.

        Makes the process a ROS node first unless it is one already (the names are
        checked before that: joining the graph waits for a missing master forever).
        """
        self.check_names()
        init_node(f"rosmc_replay_{os.getpid()}")
        for topic, msg_type in TYPES.items():
            name = self._config.topic(topic)
            self._publishers[topic] = rospy.Publisher(
                name, msg_type, queue_size=1000, latch=topic in LATCHED
            )
        self._publish_snapshot(self._history.at_time(self._config.start).revision)
        for topic in CURRENT_AT_START:
            before = [r for r in self._before if r.topic == topic]
            if before:
                self._publishers[topic].publish(before[-1].message)
        service = rospy.Service(
            self._config.topic(GET_MISSION), wire_srv.GetMission, self._on_get_mission
        )
        rospy.on_shutdown(self._stop.set)
        try:
            return self._play()
        finally:
            service.shutdown()

    def _play(self) -> int:
        if self._stop.wait(WARM_UP):
            return self._revision
        began = time.monotonic()
        last_snapshot = began
        for index, record in enumerate(self._records):
            due = began + (self._offset(record) - self._config.start) / self._config.rate
            if self._stop.wait(max(0.0, due - time.monotonic())):
                break
            replaced = self._publish(record)
            following = self._records[index + 1] if index + 1 < len(self._records) else None
            now = time.monotonic()
            quiet = (
                following is None
                or (self._offset(following) - self._offset(record)) / self._config.rate >= QUIET
            )
            if replaced or quiet or now - last_snapshot >= MAX_DELAY:
                if self._latest > self._revision:
                    self._publish_snapshot(self._latest)
                last_snapshot = now
        self._stop.wait(LINGER)
        return self._revision

    def _offset(self, record: JournalRecord) -> float:
        return self._history.seconds(record.log_time)

    def _publish(self, record: JournalRecord) -> bool:
        """Publish one record; True if it replaced the mission (publish its snapshot now)."""
        msg = record.message
        if record.topic == interface.MISSION_TOPIC:
            if int(msg.revision) > self._revision:  # a revision the history could not rebuild
                self._publishers[interface.MISSION_TOPIC].publish(msg)
                self._revision, self._snapshot = int(msg.revision), msg
            return False
        if record.topic == interface.EVENTS_TOPIC:
            revision = int(msg.revision)
            if revision <= self._revision:
                return False  # part of the snapshot already published
            self._publishers[interface.EVENTS_TOPIC].publish(msg)
            self._latest, self._stamp = max(self._latest, revision), msg.stamp.to_sec()
            if self._on_event is not None:
                self._on_event(revision, _decoded(msg), self._offset(record))
            return bool(msg.kind == EventKind.MISSION_REPLACED)
        self._publishers[record.topic].publish(msg)
        return False

    def _publish_snapshot(self, revision: int) -> None:
        try:
            state = self._history.at_revision(revision)
        except NotFound:
            return  # not rebuilt (a gap in the recording): its recorded snapshot follows
        msg = mission_to_msg(state.content(), revision, self._stamp)
        self._publishers[interface.MISSION_TOPIC].publish(msg)
        self._revision, self._snapshot = revision, msg
        _log.debug("replay: snapshot of revision %d", revision)

    def _on_get_mission(self, _request: Any) -> Any:
        return wire_srv.GetMissionResponse(mission=self._snapshot)


def _decoded(msg: Any) -> MissionEvent | None:
    try:
        return event_from_msg(msg)
    except RosmcError:
        return None


def _log_time(record: JournalRecord) -> int:
    return record.log_time
