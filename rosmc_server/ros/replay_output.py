"""The publishers of a replay: one per recorded topic, behind the replay's prefix.

Besides publishing each record as it comes, :meth:`ReplayOutput.publish_state_at` sends
what a subscriber needs to be current at a position of the recording (at the start and
after a seek): the latest agent states, TF, site and score recorded until then. TF stamps
after a seek back are shifted forward (:class:`~rosmc_server.recording.playback.StampShift`),
since TF listeners drop transforms older than the ones they hold.

Publishes (each name behind the prefix): every topic of :data:`TYPES`, latched as the live
publishers latch them (:data:`~rosmc_server.recording.channels.LATCHED_TOPICS`).
"""

from __future__ import annotations

import copy
from collections.abc import Callable
from typing import Any

import genpy
import rosmc.msg as wire
import rospy
from tf2_msgs.msg import TFMessage
from visualization_msgs.msg import Marker, MarkerArray

from .. import interface
from ..recording.channels import LATCHED_TOPICS
from ..recording.playback import Playlist, StampShift

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

    def __init__(self, prefix: str) -> None:
        self._publishers = {
            topic: rospy.Publisher(
                interface.prefixed(topic, prefix),
                msg_type,
                queue_size=1000,
                latch=topic in LATCHED_TOPICS,  # a late rviz still gets the site
            )
            for topic, msg_type in TYPES.items()
        }
        self._tf = StampShift()
        self._shown: set[str] = set()  # topics of CURRENT_AT_START published so far

    def publish(self, topic: str, msg: Any) -> None:
        """Publish one recorded message on its topic (TF with the current stamp shift)."""
        if topic == interface.TF_TOPIC:
            msg = self._shifted(msg)
        self._publishers[topic].publish(msg)
        if topic in CURRENT_AT_START:
            self._shown.add(topic)

    def publish_state_at(self, playlist: Playlist, position: float, *, moved: bool) -> None:
        """Publish the newest agent states, TF, site and score recorded until ``position``.

        A topic with nothing recorded until then that was published before (a seek back)
        gets its empty form: no agents, no score, a site cleared. ``moved``: after a seek.
        """
        if moved:
            self._tf.moved()
        for topic in CURRENT_AT_START:
            record = playlist.latest(topic, position)
            if record is not None:
                self.publish(topic, record.message)
            elif topic in self._shown and topic in EMPTY:
                self._publishers[topic].publish(EMPTY[topic]())

    def _shifted(self, msg: Any) -> Any:
        """``msg`` (a TFMessage) with its stamps moved past those published before a seek."""
        shift = self._tf.apply([t.header.stamp.to_nsec() for t in msg.transforms])
        if not shift:
            return msg
        moved = copy.deepcopy(msg)
        for transform in moved.transforms:
            transform.header.stamp = genpy.Time(0, transform.header.stamp.to_nsec() + shift)
        return moved
