"""What the simulated robots can do: each skill's run, stepped with the simulation.

A *skill run* is the simulated controllers' run of one skill (``rosmc/SkillRun`` asks
for it); a robot's *task* is its skills in order, which this module never sees.

Each skill function is a generator that sets the robot moving or working and yields
progress text while it waits for the world to catch up; it returns a closing
text on success and raises :class:`SkillFailed` with the reason on failure.
:class:`SkillRunner` steps it, pauses it (the robot holds still and resumes
the same path), cancels it, and fails it when the battery runs empty.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Generator, Mapping
from dataclasses import dataclass
from typing import Any

from .planner import NoPath
from .sim import Robot, Simulation

Steps = Generator[str, None, str]
SkillFunction = Callable[[Simulation, Robot, Mapping[str, Any]], Steps]


class SkillFailed(Exception):
    """A skill run cannot go on; the message is the reason the operator reads."""


@dataclass(frozen=True)
class RunResult:
    """How a skill run ended."""

    success: bool
    text: str


class SkillRunner:
    """Runs one skill of one robot."""

    def __init__(
        self,
        sim: Simulation,
        robot: Robot,
        function: SkillFunction,
        params: Mapping[str, Any],
        needs_power: bool = True,
    ) -> None:
        self._sim = sim
        self._needs_power = needs_power
        self._robot = robot
        self._steps = function(sim, robot, params)
        self.progress = ""
        self.paused = False
        self.result: RunResult | None = None
        self._saved: tuple[list[tuple[float, float]], float | None, str, float | None] = (
            [],
            None,
            "idle",
            None,
        )

    def update(self) -> RunResult | None:
        """Advance the run by one simulation step; the result once finished."""
        if self.result is not None or self.paused:
            return self.result
        if self._needs_power and self._robot.battery <= 0.0:
            return self._end(False, "battery empty")
        try:
            self.progress = next(self._steps)
        except StopIteration as done:
            return self._end(True, str(done.value or ""))
        except (SkillFailed, NoPath) as failure:
            return self._end(False, str(failure))
        except KeyError as missing:
            return self._end(False, f"missing parameter {missing}")
        except (TypeError, ValueError, AttributeError) as error:
            return self._end(False, f"invalid parameters: {error}")
        return None

    def pause(self) -> None:
        """Hold still; the run resumes where it was."""
        if not self.paused and self.result is None:
            self.paused = True
            robot = self._robot
            self._saved = (list(robot.path), robot.target_z, robot.activity, robot.charging_to)
            self._sim.halt(robot)
            robot.activity = "idle"  # work stops too: its clock (Robot.worked) holds still
            robot.charging_to = None

    def resume(self) -> None:
        """Go on after a pause."""
        if self.paused:
            self.paused = False
            robot = self._robot
            robot.path, robot.target_z, robot.activity, robot.charging_to = self._saved

    def cancel(self) -> None:
        """Stop for good."""
        if self.result is None:
            self._end(False, "cancelled")

    def _end(self, success: bool, text: str) -> RunResult:
        self._steps.close()  # an interrupted run cleans up (e.g. an identification session)
        self._sim.halt(self._robot)
        self._robot.activity = "idle"
        self._robot.charging_to = None
        self.result = RunResult(success, text)
        return self.result


# -- building blocks ----------------------------------------------------------------
def _drive(sim: Simulation, robot: Robot, x: float, y: float, speed: float, what: str) -> Steps:
    """Move to (x, y) along a planned path, yielding the distance left."""
    if robot.kind == "drone" and not robot.flying:
        raise SkillFailed("the drone must take off first")
    if robot.kind != "drone" and robot.z > 0.05:
        raise SkillFailed("the rover cannot move from here")
    sim.go(robot, sim.plan(robot, x, y), speed)
    while robot.path:
        left = math.hypot(robot.path[-1][0] - robot.x, robot.path[-1][1] - robot.y)
        yield f"{what}: {left:.1f} m to go"
    return ""


def _work(sim: Simulation, robot: Robot, seconds: float, what: str) -> Steps:
    """Stand still and work for ``seconds`` of sim time (a pause does not count)."""
    end = robot.worked + seconds
    robot.activity = "work"
    while robot.worked < end - 1e-9:
        yield f"{what}: {end - robot.worked:.0f} s left"
    robot.activity = "idle"
    return ""


def _climb(sim: Simulation, robot: Robot, altitude: float) -> Steps:
    robot.target_z = altitude
    while robot.moving:
        yield f"altitude {robot.z:.1f} m"
    return ""


def _pose(params: Mapping[str, Any], name: str) -> tuple[float, float, float]:
    pose = params[name]
    return float(pose.x), float(pose.y), float(pose.yaw)


def _area(params: Mapping[str, Any]) -> list[tuple[float, float]]:
    corners = [(float(p["x"]), float(p["y"])) for p in params["area"]]
    if len(corners) < 3:
        raise SkillFailed("an area needs at least three corners")
    return corners


def _sweep(area: list[tuple[float, float]], spacing: float) -> list[tuple[float, float]]:
    """Lawnmower waypoints over the area's bounding box."""
    xs, ys = [c[0] for c in area], [c[1] for c in area]
    lanes = max(1, math.ceil((max(ys) - min(ys)) / spacing))
    points = []
    for lane in range(lanes + 1):
        y = min(ys) + lane * (max(ys) - min(ys)) / lanes
        row = [(min(xs), y), (max(xs), y)]
        points += row if lane % 2 == 0 else row[::-1]
    return points


def free_stop(
    sim: Simulation, robot: Robot, x: float, y: float, radius: float
) -> tuple[float, float]:
    """A point ``radius`` from (x, y) that a rover can stand on, closest to its own side."""
    facing = math.atan2(robot.y - y, robot.x - x)
    for turn in (0, 1, -1, 2, -2, 3, -3, 4, -4, 5, -5, 6):
        angle = facing + turn * math.pi / 6
        stop = (x + radius * math.cos(angle), y + radius * math.sin(angle))
        if robot.kind == "drone" or sim.grid.free(*sim.grid.cell(stop)):
            return stop
    return (x + radius * math.cos(facing), y + radius * math.sin(facing))


# -- the skills ----------------------------------------------------------------------
def navigate_to(sim: Simulation, robot: Robot, params: Mapping[str, Any]) -> Steps:
    """Go to a pose (rovers around obstacles, the drone straight at its altitude)."""
    x, y, yaw = _pose(params, "target")
    yield from _drive(sim, robot, x, y, float(params.get("speed", robot.spec.speed)), "driving")
    while abs((yaw - robot.yaw + math.pi) % (2 * math.pi) - math.pi) > 0.05:
        turn = (yaw - robot.yaw + math.pi) % (2 * math.pi) - math.pi
        robot.yaw += max(-0.06, min(0.06, turn))
        yield "turning to the target heading"
    return f"arrived at ({x:.1f}, {y:.1f})"


def take_off(sim: Simulation, robot: Robot, params: Mapping[str, Any]) -> Steps:
    """Climb to the given altitude."""
    robot.flying = True
    yield from _climb(sim, robot, float(params["altitude"]))
    return f"flying at {robot.z:.1f} m"


def land(sim: Simulation, robot: Robot, params: Mapping[str, Any]) -> Steps:
    """Descend and land where the drone is."""
    yield from _climb(sim, robot, 0.0)
    robot.flying = False
    return "landed"


def fly_over(sim: Simulation, robot: Robot, params: Mapping[str, Any]) -> Steps:
    """Cover an area in lanes, discovering the regions in it."""
    area = _area(params)
    if not robot.flying:
        raise SkillFailed("the drone must take off first")
    yield from _climb(sim, robot, float(params.get("altitude", robot.z)))
    found: list[str] = []
    lanes = _sweep(area, float(params.get("spacing", 4.0)))
    for number, (x, y) in enumerate(lanes, 1):
        sim.go(robot, [(x, y)], robot.spec.speed)
        while robot.path:
            found += sim.reveal_around(robot, area)
            yield f"covering the area: leg {number} of {len(lanes)}"
    return f"found {', '.join(found)}" if found else "found no region"


def explore(sim: Simulation, robot: Robot, params: Mapping[str, Any]) -> Steps:
    """Drive around an area, discovering the regions in it."""
    area = _area(params)
    found: list[str] = []
    for number, (x, y) in enumerate(_sweep(area, 6.0), 1):
        try:
            path = sim.plan(robot, x, y)
        except NoPath:
            continue  # a corner inside a rock: skip it, the others still cover the area
        sim.go(robot, path, robot.spec.speed)
        while robot.path:
            found += sim.reveal_around(robot, area)
            yield f"exploring: waypoint {number}"
    return f"found {', '.join(found)}" if found else "found no region"


def return_to_lander(sim: Simulation, robot: Robot, params: Mapping[str, Any]) -> Steps:
    """Go back to the lander (the drone lands on it)."""
    if robot.kind == "drone":
        if not robot.flying:
            raise SkillFailed("the drone must take off first")
        yield from _drive(sim, robot, 0.0, 0.0, robot.spec.speed, "returning")
        yield from land(sim, robot, params)
        return "landed on the lander"
    x, y = free_stop(sim, robot, 0.0, 0.0, sim.scenario.charge_radius - 0.3)
    yield from _drive(
        sim,
        robot,
        x,
        y,
        robot.spec.speed,
        "returning",
    )
    return "at the lander"


def recharge(sim: Simulation, robot: Robot, params: Mapping[str, Any]) -> Steps:
    """Charge at the lander up to a battery level."""
    if not sim.at_lander(robot):
        raise SkillFailed("not at the lander: return to it first")
    level = min(1.0, max(0.0, float(params.get("level", 1.0))))  # above 1 would never end
    robot.charging_to = level
    while robot.battery < level - 1e-6:
        yield f"charging: {robot.battery * 100:.0f} %"
    robot.charging_to = None
    return f"battery at {robot.battery * 100:.0f} %"
