"""The simulator's radio model on ROS: ``/rosmc/sim/coverage`` (rosmc/CoverageGrid, latched).

Published at start and again whenever the radio sources change (a Wi-Fi box deployed,
moved or picked up), looked at every :data:`CHECK_PERIOD` wall seconds. The server's
coverage estimate and rviz's coverage layer read it.
"""

from __future__ import annotations

import rosmc.msg as wire
import rospy

from rosmc_server.conversions.coverage import prediction_to_msg
from rosmc_server.interface import COVERAGE_MODEL_TOPIC, MAP_FRAME

from ..core.coverage_model import coverage_prediction
from ..core.sim import Simulation
from .timing import Throttle

CHECK_PERIOD = 1.0


class CoveragePublisher:
    """Publishes the radio model's coverage when its sources change."""

    def __init__(self, sim: Simulation) -> None:
        self.sim = sim
        self._publisher = rospy.Publisher(
            COVERAGE_MODEL_TOPIC, wire.CoverageGrid, queue_size=1, latch=True
        )
        self._sources: tuple[tuple[float, float], ...] | None = None
        self._throttle = Throttle(CHECK_PERIOD)

    def after_step(self, now: float) -> None:
        """Publish anew if the sources changed (checked when due at wall time ``now``)."""
        if not self._throttle.due(now):
            return
        sources = tuple((round(x, 1), round(y, 1)) for x, y in self.sim.wifi_sources())
        if sources == self._sources:
            return
        self._sources = sources
        msg = prediction_to_msg(coverage_prediction(self.sim), MAP_FRAME)
        msg.stamp = rospy.Time.from_sec(self.sim.time)
        self._publisher.publish(msg)
