"""A node that latches one site map on ``/rosmc/site`` until stopped (for the trust tests).

Usage: ``python -m tests.integration.site_sender NODE_NAME OBSTACLES RADIUS`` publishes the
site 'from_<NODE_NAME>' (-40..40 m) with OBSTACLES cylinders of RADIUS m along y = 0.
"""

from __future__ import annotations

import sys

import rosmc.msg as wire
import rospy

from rosmc_server.conversions import site_to_msg
from rosmc_server.core.world.site import Footprint, Shape, SiteModel
from rosmc_server.interface import SITE_TOPIC


def site(name: str, count: int, radius: float) -> SiteModel:
    """The site this node publishes."""
    obstacles = tuple(
        Footprint(f"rock_{i}", Shape.CYLINDER, -30.0 + (i % 60), 0.0, radius) for i in range(count)
    )
    return SiteModel(name, (-40.0, 40.0, -40.0, 40.0), obstacles)


def main() -> None:
    """Publish the site latched, then wait to be stopped."""
    name, count, radius = sys.argv[1], int(sys.argv[2]), float(sys.argv[3])
    rospy.init_node(name, disable_signals=False)
    publisher = rospy.Publisher(SITE_TOPIC, wire.SiteMap, queue_size=1, latch=True)
    publisher.publish(site_to_msg(site(f"from_{name}", count, radius), rospy.get_time()))
    print("site published", flush=True)
    rospy.spin()


if __name__ == "__main__":
    main()
