"""The site map <-> messages: ``rosmc/SiteMap`` (the map provider sends it, the server reads it).

Part of :mod:`rosmc_server.conversions`, the one boundary between the ``rosmc``
messages and the core.
"""

from __future__ import annotations

import rosmc.msg as wire

from ..core import InvalidRequest
from ..core.world.site import Footprint, GroundRobot, Shape, SiteModel, check_site
from ..core.world.site_source import SiteInForce
from ..interface import MAP_FRAME
from .values import time_to_msg


def site_to_msg(site: SiteModel, stamp: float) -> wire.SiteMap:
    """A site as ``rosmc/SiteMap`` in the map frame, stamped ``stamp`` seconds."""
    x_min, x_max, y_min, y_max = site.bounds
    return wire.SiteMap(
        stamp=time_to_msg(stamp),
        name=site.name,
        frame_id=MAP_FRAME,
        x_min=x_min,
        x_max=x_max,
        y_min=y_min,
        y_max=y_max,
        obstacles=[
            wire.SiteObstacle(
                name=o.name,
                shape=int(o.shape),
                x=o.x,
                y=o.y,
                radius=o.radius,
                size_x=o.size_x,
                size_y=o.size_y,
                yaw=o.yaw,
                height=o.height,
            )
            for o in site.obstacles
        ],
        robots=[
            wire.SiteRobot(
                agent=r.agent, kind=r.kind, clearance=r.clearance, edge_margin=r.edge_margin
            )
            for r in site.robots
        ],
    )


def site_from_msg(msg: wire.SiteMap) -> SiteModel:
    """``rosmc/SiteMap`` as a core site (InvalidRequest if a mission cannot check against it)."""
    if msg.frame_id not in ("", MAP_FRAME):
        raise InvalidRequest(f"site '{msg.name}' is in frame '{msg.frame_id}', not '{MAP_FRAME}'")
    try:
        obstacles = tuple(
            Footprint(
                o.name, Shape(o.shape), o.x, o.y, o.radius, o.size_x, o.size_y, o.yaw, o.height
            )
            for o in msg.obstacles
        )
    except ValueError as error:
        raise InvalidRequest(f"site '{msg.name}' has an obstacle of unknown shape") from error
    robots = tuple(GroundRobot(r.agent, r.kind, r.clearance, r.edge_margin) for r in msg.robots)
    bounds = (msg.x_min, msg.x_max, msg.y_min, msg.y_max)
    return check_site(SiteModel(msg.name, bounds, obstacles, robots))


def site_in_force_to_msg(source: SiteInForce) -> wire.SiteInForce:
    """The site map in force, its sender and when the server took it, as a message."""
    return wire.SiteInForce(
        received=time_to_msg(source.received),
        sender=source.sender,
        site=site_to_msg(source.site, source.received),
    )


def site_in_force_from_msg(msg: wire.SiteInForce) -> SiteInForce | None:
    """``rosmc/SiteInForce`` as core; None for the empty message (no map in force yet).

    InvalidRequest if its map is not one a mission would take.
    """
    if not msg.sender and not msg.site.name and not msg.site.obstacles:
        return None
    return SiteInForce(site_from_msg(msg.site), msg.sender, msg.received.to_sec())
