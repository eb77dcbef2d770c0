"""The site map in force, for clients: which map, from which node, since when.

Subscribes ``/rosmc/site_in_force`` (rosmc/SiteInForce, latched by the mission server or a
replay; behind a replay's prefix when given).
"""

from __future__ import annotations

from collections.abc import Callable

import rosmc.msg as wire

from ... import interface
from ...conversions import site_in_force_from_msg
from ...core import InvalidRequest
from ...core.world.site_source import SiteInForce
from .latched import LatchedWatch


def _site(msg: wire.SiteInForce) -> SiteInForce | None:
    try:
        return site_in_force_from_msg(msg)
    except InvalidRequest:  # the server never publishes one; a foreign publisher might
        return None


class SiteWatch(LatchedWatch[SiteInForce | None]):
    """Follows the site map in force; ``on_site`` hears each (None: no map) on a ROS thread.

    The process must be a ROS node already.
    """

    def __init__(
        self, prefix: str = "", on_site: Callable[[SiteInForce | None], None] | None = None
    ) -> None:
        topic = interface.prefixed(interface.SITE_IN_FORCE_TOPIC, prefix)
        super().__init__(topic, wire.SiteInForce, _site, on_site)
