"""The mission's science on ROS: ``/rosmc/sim/science`` (rosmc/ScienceState, latched).

Published when something happens (a region discovered, stones identified, a
stone picked or delivered, a box deployed) and every :data:`HEARTBEAT_PERIOD`
wall seconds otherwise. Each message lists the discovered regions with the
stones left in them and who identified them (``""``, ``"science_rover"`` or
``"collaborative"``), the score, the stones delivered, and the event lines
since the previous message.
"""

from __future__ import annotations

import rosmc.msg as wire
import rospy

from ..core.sim import LEVEL_COLLABORATIVE, LEVEL_SCIENCE, RegionState, Simulation
from .timing import Throttle
from .topics import SCIENCE_TOPIC

HEARTBEAT_PERIOD = 1.0
IDENTIFIED_BY = {LEVEL_SCIENCE: "science_rover", LEVEL_COLLABORATIVE: "collaborative"}


def science_state(sim: Simulation, events: list[str]) -> wire.ScienceState:
    """The science state of ``sim`` as a message, with the given new event lines."""
    return wire.ScienceState(
        stamp=rospy.Time.from_sec(sim.time),
        regions=[_region(sim, r) for r in sim.regions.values() if r.discovered],
        score=sim.score,
        stones_delivered=sim.delivered,
        events=events,
    )


def _region(sim: Simulation, region: RegionState) -> wire.SampleRegion:
    spec = region.spec
    left = sim.stones_left(spec.name)
    return wire.SampleRegion(
        name=spec.name,
        x=spec.x,
        y=spec.y,
        radius=spec.radius,
        max_score=spec.max_score,
        stones_left=left,
        identified_by=IDENTIFIED_BY.get(region.identified, ""),
    )


class SciencePublisher:
    """Publishes the science state on change and as a heartbeat."""

    def __init__(self, sim: Simulation) -> None:
        self.sim = sim
        self._seen = 0
        self._heartbeat = Throttle(HEARTBEAT_PERIOD)
        self._publisher = rospy.Publisher(
            SCIENCE_TOPIC, wire.ScienceState, queue_size=10, latch=True
        )

    def after_step(self, now: float) -> None:
        """Publish if there are new events, or if the heartbeat is due."""
        if len(self.sim.events) != self._seen or self._heartbeat.due(now):
            events = self.sim.events[self._seen :]
            self._seen = len(self.sim.events)
            self._publisher.publish(science_state(self.sim, events))
