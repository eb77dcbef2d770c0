"""The mission server's ear for the site: the map its skill targets are checked against.

Subscribes ``/rosmc/site`` (rosmc/SiteMap, latched; the simulator publishes it, a real
site's map provider would too). Each sane map replaces the previous one in the mission's
:class:`~rosmc_server.core.world.site.SiteGuard`, under the server lock and nothing else, so the
server never waits on the map provider: until a map arrives (or if none ever does) the
checks are skipped, and the log says so.

ROS 1 lets any node publish there, so a map is checked first
(:func:`~rosmc_server.core.world.site.check_site`: finite numbers within bounds, a bounded
obstacle count); one that fails is refused with a WARN naming the node that sent it, and
the map in force stays.

Publishes ``/rosmc/site_in_force`` (rosmc/SiteInForce, latched): the map in force, its
sender and when it was taken; the same message is journaled for replays.
"""

from __future__ import annotations

import logging
import time
from collections.abc import Callable
from contextlib import AbstractContextManager
from typing import Protocol

import rosmc.msg as wire
import rospy

from ..conversions import site_from_msg, site_in_force_to_msg
from ..core import InvalidRequest, Mission
from ..core.world.site_source import SiteInForce
from ..interface import SITE_IN_FORCE_TOPIC, SITE_TOPIC
from ..recording import JournalWriter
from .caller_id import caller_id

_log = logging.getLogger(__name__)

UNKNOWN_SENDER = "an unknown node"


class SiteHost(Protocol):
    """What the listener needs from the mission server."""

    @property
    def mission(self) -> Mission:
        """The mission (Unavailable once the journal failed)."""

    def locked(self) -> AbstractContextManager[object]:
        """The server lock, as a context manager."""


class SiteListener:
    """Hands every sane site map that arrives to the mission (see the module docstring)."""

    def __init__(self, host: SiteHost, journal: Callable[[], JournalWriter]) -> None:
        self._host = host
        self._journal = journal
        self.in_force: SiteInForce | None = None
        _log.info("skill targets are checked against the site once a map arrives on %s", SITE_TOPIC)
        self._publisher = rospy.Publisher(
            SITE_IN_FORCE_TOPIC, wire.SiteInForce, queue_size=1, latch=True
        )
        self._publisher.publish(wire.SiteInForce())  # "no map yet": clients need not wait
        self._subscriber = rospy.Subscriber(SITE_TOPIC, wire.SiteMap, self._on_site, queue_size=1)

    def _on_site(self, msg: wire.SiteMap) -> None:
        sender = caller_id(msg) or UNKNOWN_SENDER
        try:
            site = site_from_msg(msg)
            with self._host.locked():
                self._host.mission.site.update(site)
                self.in_force = SiteInForce(site, sender, rospy.get_time())
                record = site_in_force_to_msg(self.in_force)
        except InvalidRequest as error:
            _log.warning(
                "site map from %s on %s refused: %s; the map in force stays (%s)",
                sender,
                SITE_TOPIC,
                error,
                "none" if self.in_force is None else f"'{self.in_force.site.name}'",
            )
            return
        self._publisher.publish(record)
        self._write(record)
        _log.info("%s; skill targets are checked against it", self.in_force.line())

    def _write(self, record: wire.SiteInForce) -> None:
        journal = self._journal()
        if journal.closed:
            return
        try:
            journal.append_telemetry(SITE_IN_FORCE_TOPIC, record, time.time_ns())
        except Exception:  # like telemetry, the site record must never take the server down
            _log.exception("cannot journal %s", SITE_IN_FORCE_TOPIC)
