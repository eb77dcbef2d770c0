"""The site the robots work on, and the checks of skill targets against it.

A map provider (the simulator, or a real site's mapping) publishes the site: its bounds,
the ground footprints of its obstacles, and how far each ground robot keeps from them and
from the edge. A skill parameter (a pose, or an area's corners) may declare a named check
with ``check:`` in the library:

* ``on_site``: the point, or every corner of the area, lies within the site's bounds
  (what a flying robot, which crosses obstacles, or an area to survey needs);
* ``reachable_ground``: a point a ground robot can stand on: on the site, at least its edge
  margin inside the edge, and at least its clearance away from every obstacle footprint.

The mission runs the checks through :class:`..rules.site_guard.SiteGuard` when a skill
is added or edited, when a task marker bound to it moves, and when a mission is loaded,
and refuses a bad target with one sentence that says where it lies and what to pick
instead. With no site
known the checks are skipped, and the first skipped check says so once in the log.
"""

from __future__ import annotations

import enum
import math
from dataclasses import dataclass

from ..errors import InvalidRequest


class SiteCheck(enum.Enum):
    """A named check of a target against the site (the library's ``check:`` values)."""

    ON_SITE = "on_site"
    REACHABLE_GROUND = "reachable_ground"


class Shape(enum.IntEnum):
    """The shape of an obstacle's footprint (numbers match ``rosmc/SiteObstacle``)."""

    CYLINDER = 0
    BOX = 1


@dataclass(frozen=True)
class Footprint:
    """An obstacle's footprint on the ground: a circle, or a rectangle turned by ``yaw``."""

    name: str
    shape: Shape
    x: float
    y: float
    radius: float = 0.0
    size_x: float = 0.0
    size_y: float = 0.0
    yaw: float = 0.0
    height: float = 0.0

    def distance(self, x: float, y: float) -> float:
        """Distance from a point to the footprint (0 on or inside it)."""
        dx, dy = x - self.x, y - self.y
        if self.shape is Shape.CYLINDER:
            return max(0.0, math.hypot(dx, dy) - self.radius)
        cos, sin = math.cos(-self.yaw), math.sin(-self.yaw)
        along, across = dx * cos - dy * sin, dx * sin + dy * cos
        return math.hypot(
            max(0.0, abs(along) - self.size_x / 2), max(0.0, abs(across) - self.size_y / 2)
        )


@dataclass(frozen=True)
class GroundRobot:
    """How far a ground robot's targets must keep from obstacles and from the site's edge."""

    agent: str
    kind: str = ""
    clearance: float = 0.0
    edge_margin: float = 0.0


@dataclass(frozen=True)
class SiteModel:
    """A site as its map provider describes it; every coordinate is in the map frame."""

    name: str
    bounds: tuple[float, float, float, float]  # x_min, x_max, y_min, y_max
    obstacles: tuple[Footprint, ...] = ()
    robots: tuple[GroundRobot, ...] = ()

    def robot(self, agent: str) -> GroundRobot:
        """What ``agent`` keeps clear of (nothing beyond the footprints if the site omits it)."""
        return next((r for r in self.robots if r.agent == agent), GroundRobot(agent))

    def problem(self, check: SiteCheck, agent: str, x: float, y: float) -> str:
        """What is wrong with (x, y) as ``agent``'s target under ``check``; "" if nothing."""
        x_min, x_max, y_min, y_max = self.bounds
        if not (x_min <= x <= x_max and y_min <= y <= y_max):
            return (
                f"lies off the site '{self.name}' (x {x_min:g} to {x_max:g} m, "
                f"y {y_min:g} to {y_max:g} m); pick a point on it"
            )
        if check is SiteCheck.ON_SITE:
            return ""
        robot = self.robot(agent)
        edge = min(x - x_min, x_max - x, y - y_min, y_max - y)
        if edge < robot.edge_margin:
            return (
                f"lies {edge:.1f} m from the site's edge, closer than {agent} keeps "
                f"({robot.edge_margin:.1f} m); pick a point farther inside"
            )
        if not self.obstacles:
            return ""
        distance, name = min((o.distance(x, y), o.name) for o in self.obstacles)
        if distance <= 0.0:
            return f"lies inside obstacle '{name}'; pick a point outside it"
        if distance < robot.clearance:
            return (
                f"lies {distance:.1f} m from obstacle '{name}', closer than {agent} keeps "
                f"({robot.clearance:.1f} m); pick a point farther from it"
            )
        return ""


MAX_COORDINATE = 100_000.0
"""Largest magnitude, in metres, of any bound, position, size or distance of a site map.

No robot team works on a site 100 km across; a number beyond it is a mistake (one obstacle of
radius 1e308 once refused every ground target)."""
MAX_OBSTACLES = 2_000
"""Most obstacles a site map may hold: every checked target is measured against each one."""
MAX_ROBOTS = 200
"""Most ground robots a site map may describe."""


def check_site(site: SiteModel) -> SiteModel:
    """Return ``site`` if a mission can check targets against it; InvalidRequest otherwise.

    A sane map has finite numbers within :data:`MAX_COORDINATE`, no negative sizes, bounds
    with an area, at most :data:`MAX_OBSTACLES` obstacles and :data:`MAX_ROBOTS` robots.
    """
    if len(site.obstacles) > MAX_OBSTACLES:
        raise InvalidRequest(
            f"site '{site.name}' has {len(site.obstacles)} obstacles, more than the "
            f"{MAX_OBSTACLES} a mission checks targets against"
        )
    if len(site.robots) > MAX_ROBOTS:
        raise InvalidRequest(
            f"site '{site.name}' describes {len(site.robots)} robots, more than {MAX_ROBOTS}"
        )
    x_min, x_max, y_min, y_max = site.bounds
    numbers = [("its bounds", n) for n in site.bounds]
    for o in site.obstacles:
        numbers += [(f"obstacle '{o.name}'", n) for n in _obstacle_numbers(o)]
        if min(o.radius, o.size_x, o.size_y, o.height) < 0:
            raise InvalidRequest(f"obstacle '{o.name}' of site '{site.name}' has a negative size")
    for r in site.robots:
        numbers += [(f"robot '{r.agent}'", r.clearance), (f"robot '{r.agent}'", r.edge_margin)]
        if min(r.clearance, r.edge_margin) < 0:
            raise InvalidRequest(
                f"robot '{r.agent}' of site '{site.name}' keeps a negative distance"
            )
    for what, number in numbers:
        if not math.isfinite(number):
            raise InvalidRequest(f"{what} of site '{site.name}' holds a number that is not finite")
        if abs(number) > MAX_COORDINATE:
            raise InvalidRequest(
                f"{what} of site '{site.name}' holds {number:g}, beyond the "
                f"{MAX_COORDINATE:g} m a site map may use"
            )
    if not (x_min < x_max and y_min < y_max):
        raise InvalidRequest(f"site '{site.name}' has bounds with no area")
    return site


def _obstacle_numbers(o: Footprint) -> tuple[float, ...]:
    return (o.x, o.y, o.radius, o.size_x, o.size_y, o.yaw, o.height)
