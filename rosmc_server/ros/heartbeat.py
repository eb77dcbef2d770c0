"""The ground station's heartbeat to every robot, so an idle robot knows it has a link.

A robot learns that it hears the ground only from what the ground sends; an idle robot in
coverage gets no commands and no report acks, and its lost-link policy would take the
quiet for an outage. Every :data:`HEARTBEAT_PERIOD` wall seconds the server sends each
robot a report ack of sequence 0, which acknowledges nothing and counts as ground contact.
Wall seconds, never ROS time: the robots count their silence on a steady wall clock (a
radio is silent for wall seconds whatever the simulation's speed), and a heartbeat paced
by sim time would flood the link at a high real-time factor and stall when ``/clock`` does.

Publishes ``/rosmc/link/<agent>/report_ack`` (rosmc/ReportAck) for every dynamic agent.
"""

from __future__ import annotations

import threading
from collections.abc import Sequence

import rosmc.msg as wire
import rospy

from .. import interface

HEARTBEAT_PERIOD = 2.0


class Heartbeat:
    """Sends the heartbeat to every robot of ``agents`` once started, until ROS shuts down."""

    def __init__(self, agents: Sequence[str]) -> None:
        self._publishers = {
            agent: rospy.Publisher(
                interface.ground_link(agent).report_ack, wire.ReportAck, queue_size=10
            )
            for agent in agents
        }
        self._stopped = threading.Event()

    def start(self) -> None:
        """Start beating in a thread of its own."""
        threading.Thread(target=self._run, name="heartbeat", daemon=True).start()

    def stop(self) -> None:
        """Stop beating (the thread ends within a period)."""
        self._stopped.set()

    def _run(self) -> None:
        while not rospy.is_shutdown() and not self._stopped.wait(HEARTBEAT_PERIOD):
            for agent, publisher in self._publishers.items():
                publisher.publish(wire.ReportAck(agent=agent, seq=0, sent=0.0))
