"""The simulated site: robots that move and drain batteries, boxes, stones, coverage, score.

:class:`Simulation` advances in fixed steps of sim time. Robots move
kinematically along paths (rovers around obstacles, the drone straight over
them at altitude), carried boxes and stones follow their carrier, batteries
drain with motion and work and recharge at the lander (a drone that runs empty
in the air comes down where it is), and Wi-Fi coverage is the lander's radius
plus every deployed Wi-Fi box's, with line of sight.
"""

from __future__ import annotations

import math
import random
from dataclasses import dataclass, field

from .planner import Grid, NoPath
from .scenario import BoxSpec, Obstacle, Region, RobotSpec, Scenario
from .world import ROBOT_SIZE, Placement, World

TURN_RATE = 1.2  # rad/s
CLIMB_RATE = 1.0  # m/s for take-off and landing
DRAIN = {"idle": 0.1, "work": 0.4, "move": 1.0, "fly": 1.0}  # x (1 / endurance) per second
CHARGE_TIME = {"drone": 120.0, "science_rover": 300.0, "manipulator_rover": 300.0}
REVEAL_RADIUS = {"drone": 6.0, "science_rover": 4.0, "manipulator_rover": 3.0}
LEVEL_NONE, LEVEL_SCIENCE, LEVEL_COLLABORATIVE = 0, 1, 2


@dataclass
class Robot:
    """A robot's live state."""

    spec: RobotSpec
    x: float
    y: float
    yaw: float
    z: float = 0.0
    battery: float = 1.0
    flying: bool = False
    activity: str = "idle"  # idle | work | move | fly (what drains the battery)
    path: list[tuple[float, float]] = field(default_factory=list)
    speed: float = 0.0
    target_z: float | None = None
    carrying: str = ""  # a box name or a stone name
    charging_to: float | None = None
    worked: float = 0.0  # sim seconds spent working (the clock of timed work; stops in pauses)

    @property
    def name(self) -> str:
        """The robot's agent name."""
        return self.spec.name

    @property
    def kind(self) -> str:
        """drone, science_rover or manipulator_rover."""
        return self.spec.kind

    def distance_to(self, x: float, y: float) -> float:
        """Ground distance to a point."""
        return math.hypot(self.x - x, self.y - y)

    @property
    def moving(self) -> bool:
        """Following a path or changing altitude."""
        return bool(self.path) or self.target_z is not None


@dataclass
class Box:
    """A payload box."""

    spec: BoxSpec
    x: float
    y: float
    z: float = 1.45
    carried_by: str = ""
    deployed: bool = False


@dataclass
class Stone:
    """A stone in a region; worth more the better it was identified."""

    name: str
    region: str
    x: float
    y: float
    level: int = LEVEL_NONE
    carried_by: str = ""
    delivered: bool = False


@dataclass
class RegionState:
    """A region for sampling stones, and what the team knows about it."""

    spec: Region
    discovered: bool = False
    identified: int = LEVEL_NONE
    sessions: dict[str, tuple[float, float | None]] = field(default_factory=dict)


class Simulation:
    """The whole site, stepped in sim time."""

    def __init__(self, scenario: Scenario, world: World | None = None, seed: int = 0) -> None:
        self.scenario = scenario
        self.world = world
        self.time = 0.0
        self.robots = {r.name: Robot(r, r.x, r.y, r.yaw) for r in scenario.robots}
        self.boxes = {b.name: Box(b, b.x, b.y) for b in scenario.boxes}
        self.regions = {g.name: RegionState(g) for g in scenario.regions}
        self.stones: dict[str, Stone] = {}
        self.score = 0.0
        self.delivered = 0
        self.events: list[str] = []
        rng = random.Random(seed)
        for region in scenario.regions:
            for k in range(region.stones):
                angle, radius = rng.uniform(0, 2 * math.pi), rng.uniform(0, region.radius * 0.7)
                name = f"{region.name} stone {k + 1}"
                stone = Stone(
                    name,
                    region.name,
                    region.x + radius * math.cos(angle),
                    region.y + radius * math.sin(angle),
                )
                self.stones[name] = stone
                if world is not None:
                    world.add_stone(name, stone.x, stone.y)
        # How far a rover's path keeps from obstacles, and half of it from the site's edge.
        self.clearance = max(max(ROBOT_SIZE[k][:2]) for k in ROBOT_SIZE) / 2 + 0.4
        # The lander is an obstacle too: rovers drive around it, never across it.
        side = 2 * scenario.lander_radius
        lander = Obstacle("lander", "box", 0.0, 0.0, 1.2, size_x=side, size_y=side)
        self.ground_obstacles = (*scenario.obstacles, lander)
        self.grid = Grid.build(scenario.bounds, self.ground_obstacles, self.clearance)

    # -- motion --------------------------------------------------------------------
    def plan(self, robot: Robot, x: float, y: float) -> list[tuple[float, float]]:
        """A path for ``robot`` to (x, y); NoPath if it cannot get there."""
        x_min, x_max, y_min, y_max = self.scenario.bounds
        if not (x_min <= x <= x_max and y_min <= y <= y_max):
            raise NoPath(f"({x:.1f}, {y:.1f}) lies outside the site")
        if robot.kind == "drone":
            return [(x, y)]
        return self.grid.plan((robot.x, robot.y), (x, y))

    def go(self, robot: Robot, path: list[tuple[float, float]], speed: float) -> None:
        """Follow ``path`` at ``speed`` (capped by the robot's own top speed)."""
        robot.path = list(path)
        robot.speed = min(speed, robot.spec.speed)

    def halt(self, robot: Robot) -> None:
        """Stop moving (altitude changes stop too)."""
        robot.path = []
        robot.target_z = None

    def step(self, dt: float) -> None:
        """Advance everything by ``dt`` seconds of sim time."""
        self.time += dt
        for robot in self.robots.values():
            self._move(robot, dt)
            self._drain(robot, dt)
        self._carry()
        if self.world is not None:
            self._sync_world()

    def _move(self, robot: Robot, dt: float) -> None:
        if robot.battery <= 0.0:
            self.halt(robot)
            if robot.z > 0.0:
                # An empty drone cannot hover: it comes down where it is (an emergency
                # landing), so over the lander it can still recharge.
                robot.z = max(0.0, robot.z - CLIMB_RATE * dt)
                robot.flying = robot.z > 0.0
            return
        if robot.target_z is not None:
            dz = robot.target_z - robot.z
            robot.z += max(-CLIMB_RATE * dt, min(CLIMB_RATE * dt, dz))
            if abs(robot.target_z - robot.z) < 1e-6:
                robot.target_z = None
        if not robot.path:
            return
        tx, ty = robot.path[0]
        dx, dy = tx - robot.x, ty - robot.y
        distance = math.hypot(dx, dy)
        wanted = math.atan2(dy, dx) if distance > 1e-6 else robot.yaw
        turn = (wanted - robot.yaw + math.pi) % (2 * math.pi) - math.pi
        robot.yaw += max(-TURN_RATE * dt, min(TURN_RATE * dt, turn))
        if abs(turn) > 0.6 and robot.kind != "drone":
            return  # rovers turn on the spot before driving on
        step = robot.speed * self.speed_factor(robot) * dt
        if step >= distance:
            robot.x, robot.y = tx, ty
            robot.path.pop(0)
        else:
            robot.x += dx / distance * step
            robot.y += dy / distance * step

    def speed_factor(self, robot: Robot) -> float:
        """Rovers are slower on slopes and rough ground."""
        if robot.kind == "drone":
            return 1.0
        for slope in self.scenario.slopes:
            if (
                abs(robot.x - slope.x) <= slope.size_x / 2
                and abs(robot.y - slope.y) <= slope.size_y / 2
            ):
                return slope.speed_factor
        return 1.0

    def _drain(self, robot: Robot, dt: float) -> None:
        if robot.activity == "work":
            robot.worked += dt
        if robot.charging_to is not None:
            if self.at_lander(robot):
                robot.battery = min(1.0, robot.battery + dt / CHARGE_TIME[robot.kind])
            return
        if robot.flying or robot.z > 0.05:
            activity = "fly"
        elif robot.moving:
            activity = "move"
        else:
            activity = robot.activity
        robot.battery = max(0.0, robot.battery - DRAIN[activity] * dt / robot.spec.endurance)

    def at_lander(self, robot: Robot) -> bool:
        """On the ground within the lander's charging radius."""
        return robot.distance_to(0.0, 0.0) <= self.scenario.charge_radius and robot.z < 0.05

    def _carry(self) -> None:
        for robot in self.robots.values():
            if robot.carrying in self.boxes:
                box = self.boxes[robot.carrying]
                box.x, box.y, box.z = robot.x, robot.y, robot.z + 0.9
            elif robot.carrying in self.stones:
                stone = self.stones[robot.carrying]
                stone.x, stone.y = robot.x, robot.y

    def _sync_world(self) -> None:
        assert self.world is not None
        for robot in self.robots.values():
            height = ROBOT_SIZE[robot.kind][2] / 2
            self.world.place(robot.name, Placement(robot.x, robot.y, robot.z + height, robot.yaw))
        for box in self.boxes.values():
            self.world.place(box.spec.name, Placement(box.x, box.y, box.z))
        for stone in self.stones.values():
            z = -5.0 if stone.delivered else (1.1 if stone.carried_by else 0.15)
            self.world.place(stone.name, Placement(stone.x, stone.y, z))
        self.world.step()

    # -- coverage ------------------------------------------------------------------
    def wifi(self, robot: Robot) -> tuple[float, bool]:
        """Signal strength (dBm) of the best source, and whether the robot is covered."""
        return self.signal_at(robot.x, robot.y, robot.z + 0.5)

    def signal_at(self, x: float, y: float, z: float = 0.5) -> tuple[float, bool]:
        """Signal strength (dBm) of the best source at a point, and whether it is covered.

        The lander's access point and every deployed Wi-Fi box are sources; an obstacle in
        the line of sight costs 20 dB and leaves the point uncovered.
        """
        sources = [(0.0, 0.0, self.scenario.lander_wifi_radius)]
        sources += [
            (b.x, b.y, b.spec.wifi_radius)
            for b in self.boxes.values()
            if b.deployed and b.spec.kind == "wifi"
        ]
        best_dbm, covered = -120.0, False
        for sx, sy, radius in sources:
            distance = max(1.0, math.hypot(x - sx, y - sy))
            sight = self._sight((sx, sy, 2.0), (x, y, z))
            dbm = -40.0 - 25.0 * math.log10(distance) - (0.0 if sight else 20.0)
            best_dbm = max(best_dbm, dbm)
            covered = covered or (distance <= radius and sight)
        return best_dbm, covered

    def wifi_sources(self) -> tuple[tuple[float, float], ...]:
        """Where the radio sources stand: the lander and each deployed Wi-Fi box."""
        boxes = [(b.x, b.y) for b in self.boxes.values() if b.deployed and b.spec.kind == "wifi"]
        return ((0.0, 0.0), *boxes)

    def _sight(self, a: tuple[float, float, float], b: tuple[float, float, float]) -> bool:
        if self.world is not None:
            return self.world.line_of_sight(a, b)
        return self.grid.segment_clear(a[:2], b[:2]) or max(a[2], b[2]) > 3.5

    # -- science ---------------------------------------------------------------------
    def reveal_around(
        self, robot: Robot, area: list[tuple[float, float]] | None = None
    ) -> list[str]:
        """Discover regions near the robot (and inside ``area`` if given)."""
        radius = REVEAL_RADIUS[robot.kind] + (robot.z * 0.5 if robot.kind == "drone" else 0.0)
        found = []
        for region in self.regions.values():
            if region.discovered:
                continue
            inside = area is None or point_in_polygon(region.spec.x, region.spec.y, area)
            if (
                inside
                and robot.distance_to(region.spec.x, region.spec.y) <= radius + region.spec.radius
            ):
                region.discovered = True
                found.append(region.spec.name)
                self.log(f"{robot.name} discovered {region.spec.name}")
        return found

    def region_at(self, x: float, y: float, margin: float = 0.0) -> RegionState | None:
        """The discovered region containing a point, if any."""
        for region in self.regions.values():
            spec = region.spec
            if region.discovered and math.hypot(x - spec.x, y - spec.y) <= spec.radius + margin:
                return region
        return None

    def stones_left(self, region: str) -> int:
        """Stones still lying in ``region`` (neither carried nor delivered)."""
        return sum(
            1
            for s in self.stones.values()
            if s.region == region and not s.carried_by and not s.delivered
        )

    def stone_value(self, stone: Stone) -> float:
        """What a stone scores when it reaches the lander."""
        region = self.regions[stone.region].spec
        if stone.level == LEVEL_COLLABORATIVE:
            return region.max_score
        if stone.level == LEVEL_SCIENCE:
            return region.max_score * self.scenario.science_only_fraction
        return self.scenario.min_score

    def log(self, text: str) -> None:
        """Record a science event (published with the science state)."""
        self.events.append(f"[{self.time:7.1f} s] {text}")


def point_in_polygon(x: float, y: float, polygon: list[tuple[float, float]]) -> bool:
    """Ray-casting point-in-polygon test."""
    inside = False
    for (x1, y1), (x2, y2) in zip(polygon, polygon[1:] + polygon[:1], strict=True):
        if (y1 > y) != (y2 > y) and x < (x2 - x1) * (y - y1) / (y2 - y1) + x1:
            inside = not inside
    return inside
