"""Scenario files: the site, its obstacles, the lander, payload boxes, robots and regions.

A scenario is YAML (``rosmc_scenario: 1``). Regions for sampling stones (RSSs)
are hidden until a robot explores the ground they lie on. A malformed file is
refused with an error naming the file, the key and the problem.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import yaml

from rosmc_server.core.documents.documents import DocumentReader, load_yaml
from rosmc_server.core.errors import RosmcError
from rosmc_server.core.world.site import Footprint, Shape

SCENARIO_VERSION = 1
ROBOT_KINDS = ("drone", "science_rover", "manipulator_rover")
BOX_KINDS = ("wifi", "sample", "lofar", "power")


class ScenarioError(RosmcError):
    """A scenario file is malformed."""


@dataclass(frozen=True)
class Obstacle:
    """A rock or ridge: a cylinder (radius) or an oriented box (size_x, size_y, yaw)."""

    name: str
    shape: str
    x: float
    y: float
    height: float
    radius: float = 0.0
    size_x: float = 0.0
    size_y: float = 0.0
    yaw: float = 0.0

    def footprint(self) -> Footprint:
        """Its footprint on the ground, as sites describe obstacles."""
        shape = Shape.CYLINDER if self.shape == "cylinder" else Shape.BOX
        sizes = (self.radius, self.size_x, self.size_y, self.yaw, self.height)
        return Footprint(self.name, shape, self.x, self.y, *sizes)


@dataclass(frozen=True)
class Slope:
    """Rough or sloped ground where rovers drive slower."""

    name: str
    x: float
    y: float
    size_x: float
    size_y: float
    speed_factor: float


@dataclass(frozen=True)
class Region:
    """A region for sampling stones: hidden until explored."""

    name: str
    x: float
    y: float
    radius: float
    max_score: float
    stones: int


@dataclass(frozen=True)
class BoxSpec:
    """A payload box; a deployed Wi-Fi box extends coverage by ``wifi_radius``."""

    name: str
    kind: str
    x: float
    y: float
    wifi_radius: float = 0.0


@dataclass(frozen=True)
class RobotSpec:
    """A robot: kind, start pose, speed, battery endurance in seconds of full drain."""

    name: str
    kind: str
    x: float
    y: float
    yaw: float
    speed: float
    endurance: float


@dataclass(frozen=True)
class Scenario:
    """Everything a simulation starts from."""

    name: str
    bounds: tuple[float, float, float, float]  # x_min, x_max, y_min, y_max
    lander_radius: float
    charge_radius: float
    lander_wifi_radius: float
    obstacles: tuple[Obstacle, ...]
    slopes: tuple[Slope, ...]
    regions: tuple[Region, ...]
    boxes: tuple[BoxSpec, ...]
    robots: tuple[RobotSpec, ...]
    latency: float = 0.0
    drop: float = 0.0
    min_score: float = 0.1
    science_only_fraction: float = 0.5
    source: str = field(default="<scenario>", compare=False)

    def robot(self, name: str) -> RobotSpec:
        """The robot called ``name``."""
        for robot in self.robots:
            if robot.name == name:
                return robot
        raise ScenarioError(f"scenario {self.name} has no robot {name!r}")


def load_scenario(path: str | Path) -> Scenario:
    """Read and check a scenario file."""
    try:
        data = load_yaml(Path(path).read_text(encoding="utf-8"))
    except OSError as error:
        raise ScenarioError(f"{path}: cannot read the scenario ({error.strerror})") from error
    except yaml.YAMLError as error:
        raise ScenarioError(f"{path}: not valid YAML") from error
    return scenario_from_dict(data, str(path))


def scenario_from_dict(data: object, source: str = "<scenario>") -> Scenario:
    """Build a scenario from parsed YAML, checking every key."""
    r = DocumentReader(source, ScenarioError)
    top = r.mapping(
        data,
        "",
        {"rosmc_scenario", "name", "site", "lander", "robots"},
        {"obstacles", "slopes", "regions", "boxes", "link", "scoring"},
    )
    if top["rosmc_scenario"] != SCENARIO_VERSION:
        r.fail("rosmc_scenario", f"unsupported version {top['rosmc_scenario']!r}")
    site = r.mapping(top["site"], "site", {"x_min", "x_max", "y_min", "y_max"}, set())
    bounds = tuple(r.number(site[k], f"site.{k}") for k in ("x_min", "x_max", "y_min", "y_max"))
    if bounds[0] >= bounds[1] or bounds[2] >= bounds[3]:
        r.fail("site", "x_min/y_min must be below x_max/y_max")
    lander = r.mapping(top["lander"], "lander", {"radius", "charge_radius", "wifi_radius"}, set())
    link = r.mapping(top.get("link", {}), "link", set(), {"latency", "drop"})
    scoring = r.mapping(top.get("scoring", {}), "scoring", set(), {"min_score", "science_only"})
    scenario = Scenario(
        name=r.text(top["name"], "name"),
        bounds=(bounds[0], bounds[1], bounds[2], bounds[3]),
        lander_radius=r.positive(lander["radius"], "lander.radius"),
        charge_radius=r.positive(lander["charge_radius"], "lander.charge_radius"),
        lander_wifi_radius=r.positive(lander["wifi_radius"], "lander.wifi_radius"),
        obstacles=tuple(
            _obstacle(r, o, f"obstacles[{i}]")
            for i, o in enumerate(r.items(top.get("obstacles", []), "obstacles"))
        ),
        slopes=tuple(
            _slope(r, s, f"slopes[{i}]")
            for i, s in enumerate(r.items(top.get("slopes", []), "slopes"))
        ),
        regions=tuple(
            _region(r, g, f"regions[{i}]")
            for i, g in enumerate(r.items(top.get("regions", []), "regions"))
        ),
        boxes=tuple(
            _box(r, b, f"boxes[{i}]") for i, b in enumerate(r.items(top.get("boxes", []), "boxes"))
        ),
        robots=tuple(
            _robot(r, name, spec, f"robots.{name}")
            for name, spec in r.mapping(top["robots"], "robots", set(), None).items()
        ),
        latency=r.number(link.get("latency", 0.0), "link.latency", minimum=0.0),
        drop=r.number(link.get("drop", 0.0), "link.drop", minimum=0.0, maximum=1.0),
        min_score=r.number(scoring.get("min_score", 0.1), "scoring.min_score", minimum=0.0),
        science_only_fraction=r.number(
            scoring.get("science_only", 0.5), "scoring.science_only", minimum=0.0, maximum=1.0
        ),
        source=source,
    )
    _check_unique(r, scenario)
    return scenario


def _obstacle(r: DocumentReader, raw: object, key: str) -> Obstacle:
    body = r.mapping(
        raw, key, {"name", "shape", "x", "y", "height"}, {"radius", "size_x", "size_y", "yaw"}
    )
    shape = body["shape"]
    if shape not in ("cylinder", "box"):
        r.fail(f"{key}.shape", f"must be cylinder or box, got {shape!r}")
    needed = ("radius",) if shape == "cylinder" else ("size_x", "size_y")
    for name in needed:
        if name not in body:
            r.fail(key, f"a {shape} needs {name}")
    return Obstacle(
        r.text(body["name"], f"{key}.name"),
        shape,
        r.number(body["x"], f"{key}.x"),
        r.number(body["y"], f"{key}.y"),
        r.positive(body["height"], f"{key}.height"),
        r.positive(body.get("radius", 1.0), f"{key}.radius"),
        r.positive(body.get("size_x", 1.0), f"{key}.size_x"),
        r.positive(body.get("size_y", 1.0), f"{key}.size_y"),
        r.number(body.get("yaw", 0.0), f"{key}.yaw"),
    )


def _slope(r: DocumentReader, raw: object, key: str) -> Slope:
    body = r.mapping(raw, key, {"name", "x", "y", "size_x", "size_y", "speed_factor"}, set())
    return Slope(
        r.text(body["name"], f"{key}.name"),
        r.number(body["x"], f"{key}.x"),
        r.number(body["y"], f"{key}.y"),
        r.positive(body["size_x"], f"{key}.size_x"),
        r.positive(body["size_y"], f"{key}.size_y"),
        r.number(body["speed_factor"], f"{key}.speed_factor", minimum=0.05, maximum=1.0),
    )


def _region(r: DocumentReader, raw: object, key: str) -> Region:
    body = r.mapping(raw, key, {"name", "x", "y", "radius", "max_score", "stones"}, set())
    stones = body["stones"]
    if isinstance(stones, bool) or not isinstance(stones, int) or stones < 1:
        r.fail(f"{key}.stones", "must be a whole number of at least 1")
    return Region(
        r.text(body["name"], f"{key}.name"),
        r.number(body["x"], f"{key}.x"),
        r.number(body["y"], f"{key}.y"),
        r.positive(body["radius"], f"{key}.radius"),
        r.positive(body["max_score"], f"{key}.max_score"),
        stones,
    )


def _box(r: DocumentReader, raw: object, key: str) -> BoxSpec:
    body = r.mapping(raw, key, {"name", "kind", "x", "y"}, {"wifi_radius"})
    if body["kind"] not in BOX_KINDS:
        r.fail(f"{key}.kind", f"must be one of {', '.join(BOX_KINDS)}, got {body['kind']!r}")
    if body["kind"] == "wifi" and "wifi_radius" not in body:
        r.fail(key, "a wifi box needs wifi_radius")
    return BoxSpec(
        r.text(body["name"], f"{key}.name"),
        body["kind"],
        r.number(body["x"], f"{key}.x"),
        r.number(body["y"], f"{key}.y"),
        r.number(body.get("wifi_radius", 0.0), f"{key}.wifi_radius", minimum=0.0),
    )


def _robot(r: DocumentReader, name: str, raw: object, key: str) -> RobotSpec:
    body = r.mapping(raw, key, {"kind", "x", "y", "speed", "endurance"}, {"yaw"})
    if body["kind"] not in ROBOT_KINDS:
        r.fail(f"{key}.kind", f"must be one of {', '.join(ROBOT_KINDS)}, got {body['kind']!r}")
    return RobotSpec(
        name,
        body["kind"],
        r.number(body["x"], f"{key}.x"),
        r.number(body["y"], f"{key}.y"),
        r.number(body.get("yaw", 0.0), f"{key}.yaw"),
        r.positive(body["speed"], f"{key}.speed"),
        r.positive(body["endurance"], f"{key}.endurance"),
    )


def _check_unique(r: DocumentReader, scenario: Scenario) -> None:
    names: set[str] = set()
    things: list[Any] = [*scenario.obstacles, *scenario.regions, *scenario.boxes, *scenario.robots]
    for thing in things:
        if thing.name in names:
            r.fail("", f"the name {thing.name!r} is used twice")
        names.add(thing.name)
    x_min, x_max, y_min, y_max = scenario.bounds
    for thing in things:
        if not (x_min <= thing.x <= x_max and y_min <= thing.y <= y_max):
            r.fail("", f"{thing.name!r} lies outside the site")
