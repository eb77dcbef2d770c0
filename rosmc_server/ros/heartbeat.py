"""The ground station's heartbeat to every robot, so an idle robot knows it has a link.

A robot learns that it hears the ground only from what the ground sends; an idle robot in
coverage gets no commands and no report acks, and its lost-link policy would take the
quiet for an outage. The server sends each robot a report ack of sequence 0, which
acknowledges nothing and counts as ground contact, often enough for that robot's policy:
:data:`~rosmc_server.core.skills.policy.CONTACTS_PER_WINDOW` times within its ``after``,
every 2 s at most and every 0.25 s at least (:func:`ground_contact_period`). A robot told
to hold after 1 s of silence thus hears the ground four times a second, and one late beat
does not make it hold in full contact.

Wall seconds, never ROS time: the robots count their silence on a steady wall clock (a
radio is silent for wall seconds whatever the simulation's speed), and a heartbeat paced
by sim time would flood the link at a high real-time factor and stall when ``/clock`` does.

Publishes ``/rosmc/link/<agent>/report_ack`` (rosmc/ReportAck) for every dynamic agent.
"""

from __future__ import annotations

import threading
import time
from collections.abc import Callable, Sequence

import rosmc.msg as wire
import rospy

from .. import interface
from ..core.skills.policy import SHORTEST_CONTACT_PERIOD


class Heartbeat:
    """Beats to every robot of ``agents`` once started, until ROS shuts down.

    ``period_of(agent)`` gives the seconds between beats to ``agent``; it is asked again
    at every step, so a new policy takes effect within :data:`SHORTEST_CONTACT_PERIOD`.
    """

    def __init__(self, agents: Sequence[str], period_of: Callable[[str], float]) -> None:
        self._publishers = {
            agent: rospy.Publisher(
                interface.ground_link(agent).report_ack, wire.ReportAck, queue_size=10
            )
            for agent in agents
        }
        self._period_of = period_of
        self._stopped = threading.Event()

    def start(self) -> None:
        """Start beating in a thread of its own."""
        threading.Thread(target=self._run, name="heartbeat", daemon=True).start()

    def stop(self) -> None:
        """Stop beating (the thread ends within a step)."""
        self._stopped.set()

    def _run(self) -> None:
        last_beat = dict.fromkeys(self._publishers, float("-inf"))
        while not rospy.is_shutdown():
            now = time.monotonic()
            for agent, publisher in self._publishers.items():
                if now - last_beat[agent] >= self._period_of(agent):
                    publisher.publish(wire.ReportAck(agent=agent, seq=0, sent=0.0))
                    last_beat[agent] = now
            if self._stopped.wait(SHORTEST_CONTACT_PERIOD):
                return
