"""The site for the mission server: ``/rosmc/site`` (rosmc/SiteMap, latched), sent once.

The simulator is the site's map provider: bounds, obstacle footprints (the lander too) and
how far each rover keeps from them (:func:`rosmc_sim.core.site_map.site_model`). The site
does not change while the simulation runs, so one latched message serves every server,
whenever it starts.
"""

from __future__ import annotations

import rosmc.msg as wire
import rospy

from rosmc_server.conversions import site_to_msg

from ..core.sim import Simulation
from ..core.site_map import site_model
from .topics import SITE_TOPIC


class SitePublisher:
    """Publishes the site once, latched."""

    def __init__(self, sim: Simulation) -> None:
        self.site = site_model(sim)
        self._publisher = rospy.Publisher(SITE_TOPIC, wire.SiteMap, queue_size=1, latch=True)
        self._publisher.publish(site_to_msg(self.site, sim.time))
