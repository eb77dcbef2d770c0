"""The publishers of a replay: one per recorded topic, behind the replay's prefix.

Besides publishing each record as it comes, :meth:`ReplayOutput.publish_state_at` sends
what a subscriber needs to be current at a position of the recording (at the start and
after a seek): the latest agent states, TF, site and score recorded until then. TF stamps
after a seek back are shifted forward (:class:`~rosmc_server.recording.playback.StampShift`),
since TF listeners drop transforms older than the ones they hold.

Publishes (each name behind the prefix): every topic of :data:`TYPES`, latched as the live
publishers latch them (:data:`~rosmc_server.recording.channels.LATCHED_TOPICS`), and the
robots' agent states and TF latched too (:data:`STANDING`): a paused replay sends them once,
and a GUI or rviz that joins later must still see where the robots stand. A robot the
server had not heard from yet is reported, once the replay stood paused, where it was first
heard (its first telemetry).
"""

from __future__ import annotations

import copy
import logging
import threading
import time
from collections.abc import Callable
from typing import Any

import genpy
import rosgraph
import rosmc.msg as wire
import rospy
from tf2_msgs.msg import TFMessage
from visualization_msgs.msg import Marker, MarkerArray

from .. import interface
from ..recording.channels import LATCHED_TOPICS
from ..recording.playback import Playlist, StampShift

_log = logging.getLogger(__name__)

TYPES: dict[str, Any] = {
    interface.MISSION_TOPIC: wire.Mission,
    interface.EVENTS_TOPIC: wire.MissionEvent,
    interface.AGENT_STATES_TOPIC: wire.AgentStates,
    interface.ROBOT_REPORTS_TOPIC: wire.RobotReport,
    interface.ROBOT_COMMANDS_TOPIC: wire.CommandRecord,
    interface.TF_TOPIC: TFMessage,
    interface.SCIENCE_TOPIC: wire.ScienceState,
    interface.WORLD_TOPIC: MarkerArray,
    interface.SITE_IN_FORCE_TOPIC: wire.SiteInForce,
    interface.LIBRARY_TOPIC: wire.Library,
}
"""Every recorded topic with its message class."""

CURRENT_AT_START = (
    interface.AGENT_STATES_TOPIC,
    interface.TF_TOPIC,
    interface.SCIENCE_TOPIC,
    interface.WORLD_TOPIC,
    interface.SITE_IN_FORCE_TOPIC,
)
"""Topics whose newest message before the position is published at the start and on a seek."""

STANDING = (interface.AGENT_STATES_TOPIC, interface.TF_TOPIC)
"""Topics whose first record stands for the moments before it: the robots stood there when
the recording began (its first agent states and TF come a moment after its first mission)."""


def first_telemetry(playlist: Playlist) -> dict[str, Any]:
    """Each robot's first recorded telemetry (where it stood when first heard), by name."""
    found: dict[str, Any] = {}
    for record in playlist.records_of(interface.AGENT_STATES_TOPIC):
        for state in record.message.agents:
            telemetry = state.telemetry
            heard = bool(telemetry.frame_id) or not telemetry.stamp.is_zero()
            if heard and state.agent not in found:
                found[state.agent] = telemetry
    return found


def _cleared_site() -> MarkerArray:
    return MarkerArray(markers=[Marker(action=Marker.DELETEALL)])


EMPTY: dict[str, Callable[[], Any]] = {
    interface.AGENT_STATES_TOPIC: wire.AgentStates,
    interface.SCIENCE_TOPIC: wire.ScienceState,
    interface.WORLD_TOPIC: _cleared_site,
    interface.SITE_IN_FORCE_TOPIC: wire.SiteInForce,
}
"""What a seek back to before a topic's first record publishes: nothing known yet."""


class ReplayOutput:
    """Publishers of every recorded topic behind ``prefix``; made once the process is a node."""

    def __init__(self, prefix: str, standing: dict[str, Any] | None = None) -> None:
        self._publishers = {
            topic: rospy.Publisher(
                interface.prefixed(topic, prefix),
                msg_type,
                queue_size=1000,
                # A late rviz still gets the site, and a paused replay's robots stand.
                latch=topic in LATCHED_TOPICS or topic in STANDING,
            )
            for topic, msg_type in TYPES.items()
        }
        self._tf = StampShift()
        self._standing = standing or {}  # first telemetry by robot: see first_telemetry
        self._stand = False  # robots not heard yet are shown where first heard (once paused)
        self._shown: set[str] = set()  # topics of CURRENT_AT_START published so far

    def wait_for_subscribers(self, timeout: float, stop: threading.Event) -> None:
        """Wait (up to ``timeout`` s, or until ``stop``) until every node that the master lists
        as a subscriber of a replayed topic is connected, so none misses the first messages.

        A subscriber connects only after the master told it of this new publisher: on a busy
        machine that takes longer than any fixed pause.
        """
        wanted = self._subscriber_counts()
        deadline = time.monotonic() + timeout
        while not all(
            self._publishers[topic].get_num_connections() >= count
            for topic, count in wanted.items()
        ):
            if stop.wait(0.02) or time.monotonic() > deadline:
                return

    def _subscriber_counts(self) -> dict[str, int]:
        """Per replayed topic, how many other nodes subscribe to it (the master's list)."""
        names = {publisher.resolved_name: topic for topic, publisher in self._publishers.items()}
        try:
            _, subscriptions, _ = rosgraph.Master(rospy.get_name()).getSystemState()
        except (OSError, rosgraph.MasterException) as error:
            _log.debug("cannot ask the master for subscribers (%s)", error)
            return {}
        own = rospy.get_name()
        return {
            names[name]: len([node for node in nodes if node != own])
            for name, nodes in subscriptions
            if name in names
        }

    def publish(self, topic: str, msg: Any) -> None:
        """Publish one recorded message on its topic (TF with the current stamp shift)."""
        if topic == interface.TF_TOPIC:
            msg = self._shifted(msg)
        elif topic == interface.AGENT_STATES_TOPIC and self._stand:
            msg = self._standing_robots(msg)
        self._publishers[topic].publish(msg)
        if topic in CURRENT_AT_START:
            self._shown.add(topic)

    def publish_state_at(
        self, playlist: Playlist, position: float, *, moved: bool, paused: bool = False
    ) -> None:
        """Publish the newest agent states, TF, site and score recorded until ``position``.

        A topic with nothing recorded until then that was published before (a seek back)
        gets its empty form: no score, a site cleared. ``moved``: after a seek.
        ``paused``: the replay stands at ``position``; then robots stand where they were
        first recorded (:data:`STANDING`) even before their first record, and from now on
        robots the server had not heard from yet are reported where they were first heard.
        (A replay that plays on republishes the records exactly as recorded.)
        """
        if moved:
            self._tf.moved()
        self._stand = self._stand or paused
        for topic in CURRENT_AT_START:
            record = playlist.latest(topic, position)
            if record is None and topic in STANDING and paused:
                record = playlist.earliest(topic)
            if record is not None:
                self.publish(topic, record.message)
            elif topic in self._shown and topic in EMPTY:
                self._publishers[topic].publish(EMPTY[topic]())

    def _standing_robots(self, msg: Any) -> Any:
        """``msg`` (AgentStates) with robots not heard yet where they were first heard.

        The server reports a robot without telemetry until it hears from it; the robot
        stood where its first telemetry puts it, not at the origin without a status.
        """
        unheard = [
            i
            for i, state in enumerate(msg.agents)
            if state.agent in self._standing
            and not state.telemetry.frame_id
            and state.telemetry.stamp.is_zero()
        ]
        if not unheard:
            return msg
        filled = copy.deepcopy(msg)
        for index in unheard:
            state = filled.agents[index]
            state.telemetry = self._standing[state.agent]
        return filled

    def _shifted(self, msg: Any) -> Any:
        """``msg`` (a TFMessage) with its stamps moved past those published before a seek."""
        shift = self._tf.apply([t.header.stamp.to_nsec() for t in msg.transforms])
        if not shift:
            return msg
        moved = copy.deepcopy(msg)
        for transform in moved.transforms:
            transform.header.stamp = genpy.Time(0, transform.header.stamp.to_nsec() + shift)
        return moved
