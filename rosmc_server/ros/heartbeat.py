"""The ground station's heartbeat to every robot, so an idle robot knows it has a link.

A robot learns that it hears the ground only from what the ground sends; an idle robot in
coverage gets no commands and no report acks, and its lost-link policy would take the
quiet for an outage. Every :data:`HEARTBEAT_PERIOD` seconds (ROS time: sim time in
simulation, where the policies count sim seconds) the server sends each robot a report
ack of sequence 0, which acknowledges nothing and counts as ground contact.

Publishes ``/rosmc/link/<agent>/report_ack`` (rosmc/ReportAck) for every dynamic agent.
"""

from __future__ import annotations

from collections.abc import Sequence

import rosmc.msg as wire
import rospy

from .. import interface

HEARTBEAT_PERIOD = 2.0


class Heartbeat:
    """Sends the heartbeat to every robot of ``agents`` once started."""

    def __init__(self, agents: Sequence[str]) -> None:
        self._publishers = {
            agent: rospy.Publisher(
                interface.ground_link(agent).report_ack, wire.ReportAck, queue_size=10
            )
            for agent in agents
        }
        self._timer: rospy.Timer | None = None

    def start(self) -> None:
        """Start beating."""
        self._timer = rospy.Timer(rospy.Duration(HEARTBEAT_PERIOD), self._beat)

    def _beat(self, _event: object) -> None:
        for agent, publisher in self._publishers.items():
            publisher.publish(wire.ReportAck(agent=agent, seq=0, sent=0.0))
