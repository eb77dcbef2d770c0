"""Named places an operator can pick for a location parameter, and a new skill's defaults.

A location parameter is one a task marker can fill (a point, a pose or an area: its
``marker_type``). The places offered for it are the mission's task markers (picking one
binds the parameter, so it follows the marker), the discovered regions for sampling
stones, the lander and the robots' current positions (picking one of those fills the
value). Each place carries the value it gives the parameter.

A newly added skill takes the place its robot was last sent to (the latest location in
its task), else the robot's own position, else the lander: never a fixed placeholder.
"""

from __future__ import annotations

import enum
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field

from ..model.model import SkillInstance, TaskMarker
from ..skills.library import ParameterSpec, SkillSpec
from ..skills.params import MarkerType, Pose, Value
from ..world.areas import DEFAULT_SIDE, centroid, square
from ..world.site import SiteCheck, SiteModel
from .science import RegionScience

LANDER = "lander"
STAND_OFF = 0.5  # metres a ground robot's target keeps beyond the lander and its clearance
REGION_MARGIN = 1.0  # metres an area around a region reaches beyond the region's radius


class PlaceKind(enum.Enum):
    """Where a place comes from."""

    MARKER = "marker"
    AREA_CENTRE = "area centre"
    REGION = "region"
    LANDER = "lander"
    ROBOT = "robot"
    TASK = "earlier skill"


@dataclass(frozen=True)
class Place:
    """A place a location parameter can take.

    ``marker``: the task marker a pick binds ("" for a place that only fills the value).
    """

    name: str
    kind: PlaceKind
    x: float
    y: float
    value: Value
    marker: str = ""

    @property
    def label(self) -> str:
        """How a picker lists it, e.g. ``RSS A — region (16, 9)``."""
        where = f"({self.x:.0f}, {self.y:.0f})"
        if self.name == self.kind.value:  # the lander: no need to say it twice
            return f"{self.name} {where}"
        return f"{self.name} \u2014 {self.kind.value} {where}"

    def fill(self, param: str) -> tuple[dict[str, Value], dict[str, str]]:
        """The ``params`` and ``bindings`` that put this place into ``param``."""
        if self.marker:
            return {}, {param: self.marker}
        return {param: self.value}, {}


@dataclass(frozen=True)
class Surroundings:
    """What is known around the mission besides its markers.

    ``robots``: each robot's current pose; ``lander``: where the lander stands (None:
    unknown).
    """

    regions: tuple[RegionScience, ...] = ()
    site: SiteModel | None = None
    robots: Mapping[str, Pose] = field(default_factory=dict)
    lander: tuple[float, float] | None = None


def is_location(param: ParameterSpec) -> bool:
    """Whether a task marker (so a place) can fill ``param``."""
    return param.marker_type is not None


def value_at(param: ParameterSpec, x: float, y: float, yaw: float = 0.0) -> Value:
    """The value ``param`` takes for a place at (x, y): a pose, or an area around it."""
    if param.marker_type is MarkerType.AREA:
        return _polygon(square(x, y, 0.0, DEFAULT_SIDE))
    if param.marker_type is MarkerType.POSITION:
        yaw = 0.0
    return Pose(x, y, 0.0, 0.0, 0.0, yaw)


def places_for(
    param: ParameterSpec, agent: str, markers: Sequence[TaskMarker], around: Surroundings
) -> list[Place]:
    """Every place ``param`` of a skill of ``agent`` can take, markers first."""
    if param.marker_type is None:
        return []
    found = [
        Place(m.name, PlaceKind.MARKER, m.pose.x, m.pose.y, m.value_for(_is_area(param)), m.name)
        for m in markers
        if param.accepts_marker(m.type)
    ]
    if not _is_area(param):
        found += [
            Place(m.name, PlaceKind.AREA_CENTRE, m.pose.x, m.pose.y, value_at(param, *_xy(m)))
            for m in markers
            if m.type is MarkerType.AREA
        ]
    bound = {p.name for p in found}
    found += [
        Place(r.name, PlaceKind.REGION, r.x, r.y, _region_value(param, r))
        for r in around.regions
        if r.name not in bound
    ]
    if around.lander is not None and not _is_area(param):
        found.append(_lander_place(param, agent, around))
    own = [(agent, around.robots[agent])] if agent in around.robots else []
    others = sorted((a, p) for a, p in around.robots.items() if a != agent)
    found += [
        Place(a, PlaceKind.ROBOT, p.x, p.y, value_at(param, p.x, p.y, p.yaw))
        for a, p in own + others
    ]
    return found


def default_place(
    param: ParameterSpec,
    agent: str,
    task: Sequence[tuple[SkillInstance, SkillSpec]],
    markers: Sequence[TaskMarker],
    around: Surroundings,
) -> Place | None:
    """The place a new skill's ``param`` should take (None: nothing is known).

    ``task`` is ``agent``'s task with each skill's spec, in order. The latest place in it
    comes first (bound to its marker where ``param`` can be), then the robot's own
    position, then the lander.
    """
    if param.marker_type is None:
        return None
    offered = [
        p for p in places_for(param, agent, markers, around) if fits(param, agent, p, around)
    ]
    latest = last_location(task)
    if latest is not None:
        skill, name = latest
        marker = skill.bindings.get(name, "")
        # the marker's own place; a point parameter takes an area marker's centre
        follows = (PlaceKind.MARKER, PlaceKind.AREA_CENTRE)
        chosen = next((p for p in offered if p.name == marker and p.kind in follows), None)
        if chosen is not None:
            return chosen
        xy = location_xy(skill.params.get(name))
        if xy is not None:
            what = skill.label or skill.skill
            earlier = Place(what, PlaceKind.TASK, *xy, value_at(param, *xy))
            if fits(param, agent, earlier, around):
                return earlier
    for kind, name in ((PlaceKind.ROBOT, agent), (PlaceKind.LANDER, LANDER)):
        chosen = next((p for p in offered if p.kind is kind and p.name == name), None)
        if chosen is not None:
            return chosen
    return None


def fits(param: ParameterSpec, agent: str, place: Place, around: Surroundings) -> bool:
    """Whether the site (if known) takes ``place`` as ``agent``'s ``param``: a default the
    server would refuse is no default."""
    site, check = around.site, param.check_target
    if site is None or check is None:
        return True
    if isinstance(place.value, list):
        corners = [location_xy(corner) for corner in place.value]
        return all(xy is not None and not site.problem(check, agent, *xy) for xy in corners)
    return not site.problem(check, agent, place.x, place.y)


def last_location(
    task: Sequence[tuple[SkillInstance, SkillSpec]],
) -> tuple[SkillInstance, str] | None:
    """The latest skill of ``task`` with a location parameter, and that parameter."""
    for skill, spec in reversed(task):
        name = first_location(spec)
        if name:
            return skill, name
    return None


def first_location(spec: SkillSpec) -> str:
    """The name of ``spec``'s first location parameter ("" if it has none)."""
    return next((p.name for p in spec.parameters if is_location(p)), "")


def location_xy(value: object) -> tuple[float, float] | None:
    """Where a location value lies: a pose's (x, y) or an area's centre (None: neither)."""
    if isinstance(value, Pose):
        return value.x, value.y
    if isinstance(value, Mapping) and {"x", "y"} <= set(value):
        return float(value["x"]), float(value["y"])
    if isinstance(value, list) and value:
        try:
            return centroid([(float(v["x"]), float(v["y"])) for v in value])
        except (KeyError, TypeError, ValueError):
            return None
    return None


def _is_area(param: ParameterSpec) -> bool:
    return param.marker_type is MarkerType.AREA


def _xy(marker: TaskMarker) -> tuple[float, float]:
    return marker.pose.x, marker.pose.y


def _polygon(corners: Sequence[tuple[float, float]]) -> Value:
    return [{"x": round(x, 3), "y": round(y, 3)} for x, y in corners]


def _region_value(param: ParameterSpec, region: RegionScience) -> Value:
    if _is_area(param):
        side = max(DEFAULT_SIDE, 2 * (region.radius + REGION_MARGIN))
        return _polygon(square(region.x, region.y, 0.0, side))
    return value_at(param, region.x, region.y)


def _lander_place(param: ParameterSpec, agent: str, around: Surroundings) -> Place:
    """The lander; for a ground robot's target, the point beside it facing the robot
    (the lander itself is an obstacle a ground target must keep clear of)."""
    assert around.lander is not None
    x, y = around.lander
    if param.check_target is SiteCheck.REACHABLE_GROUND:
        x, y = _beside_lander(agent, around)
    return Place(LANDER, PlaceKind.LANDER, x, y, value_at(param, x, y))


def _beside_lander(agent: str, around: Surroundings) -> tuple[float, float]:
    assert around.lander is not None
    lx, ly = around.lander
    reach, keep = 0.0, 0.0
    if around.site is not None:
        footprint = next((o for o in around.site.obstacles if o.name == LANDER), None)
        if footprint is not None:
            reach = max(footprint.radius, math.hypot(footprint.size_x, footprint.size_y) / 2)
        keep = around.site.robot(agent).clearance
    robot = around.robots.get(agent)
    heading = math.atan2(robot.y - ly, robot.x - lx) if robot is not None else 0.0
    if robot is not None and robot.x == lx and robot.y == ly:
        heading = 0.0
    distance = reach + keep + STAND_OFF
    return lx + distance * math.cos(heading), ly + distance * math.sin(heading)
