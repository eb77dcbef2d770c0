"""The science and manipulation skills: identify, pick and deliver stones; carry boxes.

Identification scores depend on who looks: the science rover alone raises a
region's stones to a fraction of its maximum score, the science and the
manipulator rover together (their identifications overlapping in time, which
a skill barrier arranges) to the maximum; an unidentified stone scores the
minimum. A stone's score counts when it reaches the lander.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any, TypeVar

from .sim import LEVEL_COLLABORATIVE, LEVEL_SCIENCE, Robot, Simulation
from .skill_runs import SkillFailed, Steps, _drive, _pose, _work, free_stop

T = TypeVar("T")

IDENTIFY_SECONDS = {"quick": 10.0, "standard": 20.0, "detailed": 40.0}
HANDLING_SECONDS = 8.0
REACH = 1.5  # how close the arm must be to what it handles


def identify_stones(sim: Simulation, robot: Robot, params: Mapping[str, Any]) -> Steps:
    """Image the stones of the region at a position (both rovers together: best score)."""
    if robot.kind == "drone":
        raise SkillFailed("the drone has no cameras for identification")
    x, y, _ = _pose(params, "position")
    reach = float(params.get("radius", 2.0))
    region = sim.region_at(x, y, margin=reach)
    if region is None:
        raise SkillFailed(f"no discovered region at ({x:.1f}, {y:.1f}): explore first")
    away = robot.distance_to(x, y) - reach - region.spec.radius
    if away > 0:
        raise SkillFailed(f"too far from {region.spec.name}: {away:.1f} m away")
    start = sim.time
    seconds = IDENTIFY_SECONDS.get(str(params.get("mode", "standard")))
    if seconds is None:
        raise SkillFailed(f"mode must be one of {', '.join(IDENTIFY_SECONDS)}")
    region.sessions[robot.kind] = (start, None)
    try:
        yield from _work(sim, robot, seconds, f"identifying stones at {region.spec.name}")
    except GeneratorExit:
        # Cancelled or failed: an open session would make the partner's later,
        # separate identification count as collaborative.
        region.sessions.pop(robot.kind, None)
        raise
    region.sessions[robot.kind] = (start, sim.time)
    partner = "manipulator_rover" if robot.kind == "science_rover" else "science_rover"
    other = region.sessions.get(partner)
    together = (
        other is not None and (other[1] is None or other[1] >= start) and other[0] <= sim.time
    )
    level = (
        LEVEL_COLLABORATIVE if together else (LEVEL_SCIENCE if robot.kind == "science_rover" else 0)
    )
    if level > region.identified:
        region.identified = level
        for stone in sim.stones.values():
            if stone.region == region.spec.name and not stone.delivered and not stone.carried_by:
                stone.level = max(stone.level, level)
        how = "together with the other rover" if together else "alone"
        sim.log(f"{robot.name} identified the stones of {region.spec.name} {how}")
    if level == 0:
        return f"looked at {region.spec.name}; the science rover must identify the stones"
    return f"stones of {region.spec.name} identified ({'collaboratively' if together else 'alone'})"


def pick_stone(sim: Simulation, robot: Robot, params: Mapping[str, Any]) -> Steps:
    """Drive to the best stone near a position and pick it up."""
    _require_arm(robot)
    if robot.carrying:
        raise SkillFailed(f"the gripper already holds {robot.carrying}")
    x, y, _ = _pose(params, "position")
    reach = float(params.get("radius", 2.0))
    region = sim.region_at(x, y, margin=reach)
    if region is None:
        raise SkillFailed(f"no discovered region at ({x:.1f}, {y:.1f}): explore first")
    stones = [
        s
        for s in sim.stones.values()
        if s.region == region.spec.name and not s.carried_by and not s.delivered
    ]
    if not stones:
        raise SkillFailed(f"no stone left at {region.spec.name}")
    stone = max(stones, key=lambda s: (s.level, -math.hypot(s.x - x, s.y - y)))
    yield from _approach(sim, robot, stone.x, stone.y, f"approaching {stone.name}")
    yield from _work(sim, robot, HANDLING_SECONDS, f"picking {stone.name}")
    stone.carried_by = robot.name
    robot.carrying = stone.name
    sim.log(f"{robot.name} picked {stone.name}")
    return f"holding {stone.name}"


def deposit_at_lander(sim: Simulation, robot: Robot, params: Mapping[str, Any]) -> Steps:
    """Bring the carried stone to the lander's sample box."""
    stone = _carried(robot, sim.stones, "a stone")
    yield from _approach(
        sim, robot, 0.0, 0.0, "driving to the lander", reach=sim.scenario.charge_radius - 0.5
    )
    yield from _work(sim, robot, HANDLING_SECONDS, "depositing the stone")
    value = sim.stone_value(stone)
    stone.delivered, stone.carried_by, robot.carrying = True, "", ""
    sim.score += value
    sim.delivered += 1
    sim.log(f"{robot.name} delivered {stone.name} worth {value:.2f}; score {sim.score:.2f}")
    return f"delivered {stone.name} (+{value:.2f})"


def pick_box(sim: Simulation, robot: Robot, params: Mapping[str, Any]) -> Steps:
    """Drive to a payload box and pick it up."""
    _require_arm(robot)
    box = sim.boxes.get(str(params["box"]))
    if box is None:
        raise SkillFailed(f"there is no box {params['box']!r}")
    if robot.carrying:
        raise SkillFailed(f"the gripper already holds {robot.carrying}")
    if box.carried_by:
        raise SkillFailed(f"{box.spec.name} is carried by {box.carried_by}")
    yield from _approach(sim, robot, box.x, box.y, f"approaching {box.spec.name}", reach=3.0)
    yield from _work(sim, robot, HANDLING_SECONDS, f"picking {box.spec.name}")
    box.carried_by, box.deployed, robot.carrying = robot.name, False, box.spec.name
    return f"holding {box.spec.name}"


def place_box(sim: Simulation, robot: Robot, params: Mapping[str, Any]) -> Steps:
    """Drive to a pose and deploy the carried box there."""
    box = _carried(robot, sim.boxes, "a box")
    x, y, _ = _pose(params, "target")
    yield from _drive(sim, robot, x, y, robot.spec.speed, f"carrying {box.spec.name}")
    yield from _work(sim, robot, HANDLING_SECONDS, f"deploying {box.spec.name}")
    box.carried_by, robot.carrying, box.deployed = "", "", True
    box.x, box.y, box.z = robot.x + math.cos(robot.yaw), robot.y + math.sin(robot.yaw), 0.25
    sim.log(f"{robot.name} deployed {box.spec.name} at ({box.x:.1f}, {box.y:.1f})")
    return f"{box.spec.name} deployed"


def _require_arm(robot: Robot) -> None:
    if robot.kind != "manipulator_rover":
        raise SkillFailed(f"{robot.name} has no arm")


def _carried(robot: Robot, things: Mapping[str, T], what: str) -> T:
    """The one of ``things`` the robot's arm holds; SkillFailed if it holds none of them."""
    _require_arm(robot)
    thing = things.get(robot.carrying)
    if thing is None:
        raise SkillFailed(f"not carrying {what}")
    return thing


def _approach(
    sim: Simulation, robot: Robot, x: float, y: float, what: str, reach: float = REACH
) -> Steps:
    """Drive until within ``reach`` of (x, y), stopping short of the point itself.

    The stop is on the robot's side of the target if that ground is free, else the
    nearest free side (a box beside the lander is reached from around the lander).
    """
    distance = robot.distance_to(x, y)
    if distance <= reach:
        return ""
    stop = free_stop(sim, robot, x, y, reach - 0.3)
    yield from _drive(sim, robot, stop[0], stop[1], robot.spec.speed, what)
    return ""
