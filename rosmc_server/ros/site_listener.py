"""The mission server's ear for the site: the map its skill targets are checked against.

Subscribes ``/rosmc/site`` (rosmc/SiteMap, latched; the simulator publishes it, a real
site's map provider would too). Each map replaces the previous one in the mission's
:class:`~rosmc_server.core.site.SiteGuard`, under the server lock and nothing else, so the
server never waits on the map provider: until a map arrives (or if none ever does) the
checks are skipped, and the log says so. A map the mission cannot check against is
logged and ignored; the last good one stays.
"""

from __future__ import annotations

import logging
from contextlib import AbstractContextManager
from typing import Protocol

import rosmc.msg as wire
import rospy

from ..conversions import site_from_msg
from ..core import InvalidRequest, Mission
from ..interface import SITE_TOPIC

_log = logging.getLogger(__name__)


class SiteHost(Protocol):
    """What the listener needs from the mission server."""

    mission: Mission

    def locked(self) -> AbstractContextManager[object]:
        """The server lock, as a context manager."""


class SiteListener:
    """Hands every site map that arrives to the mission (see the module docstring)."""

    def __init__(self, host: SiteHost) -> None:
        self._host = host
        _log.info("skill targets are checked against the site once a map arrives on %s", SITE_TOPIC)
        self._subscriber = rospy.Subscriber(SITE_TOPIC, wire.SiteMap, self._on_site, queue_size=1)

    def _on_site(self, msg: wire.SiteMap) -> None:
        try:
            site = site_from_msg(msg)
            with self._host.locked():
                self._host.mission.site.update(site)
        except InvalidRequest as error:
            _log.warning("site map on %s ignored: %s", SITE_TOPIC, error)
            return
        _log.info(
            "site '%s' from %s: %d obstacles, %d ground robots; skill targets are checked "
            "against it",
            site.name,
            SITE_TOPIC,
            len(site.obstacles),
            len(site.robots),
        )
