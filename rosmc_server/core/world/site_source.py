"""Which site map is in force: the map, the node that sent it, and when the server took it.

ROS 1 lets any node publish on ``/rosmc/site``; the operator should see whose map the
mission checks targets against, in ``rosmc status``, the command GUI and a replay.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

from .site import SiteModel

NO_SITE = "site: no map in force (skill targets are not checked against the site)"


@dataclass(frozen=True)
class SiteInForce:
    """A site map the mission server accepted, with its sender's node name."""

    site: SiteModel
    sender: str
    received: float  # seconds on the server's clock (sim or wall time)

    def line(self) -> str:
        """One line for an operator, e.g. ``site 'mars' from /rosmc/sim at 10:04:05: ...``."""
        return (
            f"site '{self.site.name}' from {self.sender or 'an unknown node'} at "
            f"{_clock(self.received)}: {len(self.site.obstacles)} obstacles, "
            f"{len(self.site.robots)} ground robots"
        )


def site_line(site: SiteInForce | None) -> str:
    """What an operator reads about the site map in force (or that there is none)."""
    return NO_SITE if site is None else site.line()


def _clock(seconds: float) -> str:
    """UTC time of day for wall-clock stamps; seconds since start for sim time."""
    if seconds > 1e9:  # after 2001: a wall-clock stamp
        return time.strftime("%H:%M:%S UTC", time.gmtime(seconds))
    return f"t={seconds:.1f} s"
