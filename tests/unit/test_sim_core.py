"""The simulation core: planner, batteries, coverage, discovery, scoring, handling, skill runs.

Runs headless pybullet (DIRECT) worlds; no ROS.
"""

from __future__ import annotations

import copy
import itertools
import math
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest

from rosmc_server.core import Pose
from rosmc_sim.core.planner import Grid, NoPath, obstacle_distance
from rosmc_sim.core.scenario import Obstacle, ScenarioError, load_scenario, scenario_from_dict
from rosmc_sim.core.sim import (
    CHARGE_TIME,
    DRAIN,
    LEVEL_COLLABORATIVE,
    LEVEL_SCIENCE,
    Robot,
    Simulation,
)
from rosmc_sim.core.skill_runs import RunResult, SkillFailed, SkillRunner
from rosmc_sim.core.skills_registry import SIM_SKILLS, sim_skill_for
from rosmc_sim.core.world import World

REPO = Path(__file__).resolve().parents[2]
MARS = REPO / "rosmc_sim" / "scenarios" / "mars_sample_return.yaml"
DT = 0.1
AREA_A = [{"x": 10, "y": 4}, {"x": 22, "y": 4}, {"x": 22, "y": 14}, {"x": 10, "y": 14}]

# A small site: one boulder east of the lander, one region beyond it.
SMALL: dict[str, Any] = {
    "rosmc_scenario": 1,
    "name": "small",
    "site": {"x_min": -30.0, "x_max": 30.0, "y_min": -30.0, "y_max": 30.0},
    "lander": {"radius": 2.0, "charge_radius": 4.5, "wifi_radius": 20.0},
    "obstacles": [
        {"name": "boulder", "shape": "cylinder", "x": 10.0, "y": 0.0, "radius": 2.0, "height": 2.0}
    ],
    "regions": [{"name": "rss", "x": 14.0, "y": 8.0, "radius": 2.0, "max_score": 1.0, "stones": 2}],
    "boxes": [{"name": "wifi_box", "kind": "wifi", "x": 2.6, "y": 0.8, "wifi_radius": 10.0}],
    "robots": {
        "drone": {"kind": "drone", "x": 0.0, "y": 0.0, "speed": 3.0, "endurance": 300.0},
        "sci": {"kind": "science_rover", "x": 3.5, "y": -3.5, "speed": 1.0, "endurance": 3600.0},
        "arm": {"kind": "manipulator_rover", "x": -3.5, "y": -3.5, "speed": 1.0, "endurance": 3600},
    },
}


@pytest.fixture
def sim() -> Iterator[Simulation]:
    """The small site in a pybullet world."""
    scenario = scenario_from_dict(copy.deepcopy(SMALL))
    world = World(scenario)
    yield Simulation(scenario, world, seed=1)
    world.close()


@pytest.fixture
def mars() -> Iterator[Simulation]:
    """The shipped Mars scenario in a pybullet world."""
    world = World(load_scenario(MARS))
    yield Simulation(load_scenario(MARS), world)
    world.close()


def runner(sim: Simulation, robot: str, skill: str, **params: Any) -> SkillRunner:
    kind = sim_skill_for(skill, sim.robots[robot].kind)
    return SkillRunner(sim, sim.robots[robot], kind.function, params, kind.needs_power)


def finish(sim: Simulation, *runners: SkillRunner, limit: float = 1000.0) -> list[RunResult]:
    """Step until every runner has a result."""
    end = sim.time + limit
    while any(r.result is None for r in runners):
        assert sim.time < end, [r.progress for r in runners]
        for r in runners:
            r.update()
        sim.step(DT)
    return [r.result for r in runners if r.result is not None]


def run(sim: Simulation, robot: str, skill: str, **params: Any) -> RunResult:
    return finish(sim, runner(sim, robot, skill, **params))[0]


def put(robot: Robot, x: float, y: float) -> None:
    robot.x, robot.y = x, y


def discover(sim: Simulation, name: str = "rss") -> None:
    sim.regions[name].discovered = True


# -- planner -------------------------------------------------------------------------
def test_planner_goes_around_an_obstacle() -> None:
    boulder = Obstacle("b", "cylinder", 0.0, 0.0, 2.0, radius=2.0)
    grid = Grid.build((-20, 20, -20, 20), [boulder], clearance=1.0)
    path = grid.plan((-10.0, 0.0), (10.0, 0.0))
    assert path[-1] == (10.0, 0.0) and len(path) >= 2
    points = [(-10.0, 0.0), *path]
    length = sum(math.dist(a, b) for a, b in itertools.pairwise(points))
    assert length > 20.0
    for a, b in itertools.pairwise(points):
        for k in range(21):
            x, y = a[0] + k / 20 * (b[0] - a[0]), a[1] + k / 20 * (b[1] - a[1])
            assert obstacle_distance(boulder, x, y) > 0.5


@pytest.mark.parametrize(
    ("goal", "reason"),
    [((0.0, 0.0), "inside an obstacle"), ((15.0, 15.0), "no path"), ((25.0, 0.0), "off the site")],
)
def test_planner_refuses_unreachable_targets(goal: tuple[float, float], reason: str) -> None:
    walls = [
        Obstacle("b", "cylinder", 0.0, 0.0, 2.0, radius=2.0),
        *(
            Obstacle(f"w{i}", "box", 15.0 + dx, 15.0 + dy, 2.0, size_x=sx, size_y=sy)
            for i, (dx, dy, sx, sy) in enumerate(
                [(0, 4, 10, 1), (0, -4, 10, 1), (4, 0, 1, 10), (-4, 0, 1, 10)]
            )
        ),
    ]
    grid = Grid.build((-20, 20, -20, 20), walls, clearance=1.0)
    with pytest.raises(NoPath, match=reason):
        grid.plan((-10.0, -10.0), goal)


def test_rover_drives_around_the_boulder(sim: Simulation) -> None:
    rover, boulder = sim.robots["sci"], sim.scenario.obstacles[0]
    put(rover, 4.0, 0.0)
    running = runner(sim, "sci", "navigate_to", target=Pose(16.0, 0.0))
    closest = math.inf
    while running.update() is None:
        sim.step(DT)
        closest = min(closest, obstacle_distance(boulder, rover.x, rover.y))
    assert running.result == RunResult(True, "arrived at (16.0, 0.0)")
    assert closest > 0.5
    assert (rover.x, rover.y) == (16.0, 0.0)


def test_navigate_to_a_target_off_the_site_fails(sim: Simulation) -> None:
    result = run(sim, "sci", "navigate_to", target=Pose(50.0, 0.0))
    assert not result.success and "outside the site" in result.text


def test_a_malformed_scenario_names_the_key() -> None:
    data = copy.deepcopy(SMALL)
    data["robots"]["sci"]["kind"] = "tank"
    with pytest.raises(ScenarioError, match=r"robots\.sci\.kind"):
        scenario_from_dict(data, "bad.yaml")


# -- battery -------------------------------------------------------------------------
def test_moving_drains_more_than_idling(sim: Simulation) -> None:
    sci, arm = sim.robots["sci"], sim.robots["arm"]
    result = run(sim, "sci", "navigate_to", target=Pose(3.5, -20.0))
    assert result.success
    moved, idled = 1.0 - sci.battery, 1.0 - arm.battery
    assert idled == pytest.approx(DRAIN["idle"] * sim.time / 3600.0, rel=0.01)
    assert moved > 5 * idled


def test_an_empty_battery_stops_the_run_and_the_robot(sim: Simulation) -> None:
    rover = sim.robots["sci"]
    rover.battery = 0.0005
    result = run(sim, "sci", "navigate_to", target=Pose(3.5, -25.0))
    assert result == RunResult(False, "battery empty")
    y = rover.y
    sim.step(1.0)
    assert rover.battery == 0.0 and rover.y == y and not rover.path


def test_recharge_at_the_lander_even_when_empty(sim: Simulation) -> None:
    rover = sim.robots["sci"]
    assert run(sim, "sci", "return_to_lander") == RunResult(True, "at the lander")
    rover.battery = 0.0
    start = sim.time
    result = run(sim, "sci", "recharge", level=0.5)
    assert result.success and rover.battery == pytest.approx(0.5, abs=1e-4)
    assert sim.time - start == pytest.approx(0.5 * CHARGE_TIME["science_rover"], abs=1.0)
    assert run(sim, "sci", "recharge", level=1.5).text == "battery at 100 %"  # clamped


def test_recharge_away_from_the_lander_fails(sim: Simulation) -> None:
    put(sim.robots["sci"], 15.0, -15.0)
    assert run(sim, "sci", "recharge") == RunResult(False, "not at the lander: return to it first")


# -- coverage and line of sight ----------------------------------------------------------
@pytest.mark.parametrize(("x", "y", "covered"), [(5.0, 5.0, True), (0.0, -25.0, False)])
def test_lander_coverage_ends_at_its_radius(
    sim: Simulation, x: float, y: float, covered: bool
) -> None:
    rover = sim.robots["sci"]
    put(rover, x, y)
    signal, inside = sim.wifi(rover)
    assert inside is covered
    assert -120.0 < signal < -40.0


def test_an_obstacle_blocks_coverage_and_weakens_the_signal(sim: Simulation) -> None:
    rover = sim.robots["sci"]
    put(rover, 16.0, 0.0)  # behind the boulder, within the lander's radius
    blocked_signal, covered = sim.wifi(rover)
    assert not covered
    put(rover, 16.0, 6.0)  # as far, in the clear
    clear_signal, covered = sim.wifi(rover)
    assert covered and clear_signal > blocked_signal + 15.0


def test_a_robot_in_between_does_not_hide_an_obstacle(sim: Simulation) -> None:
    put(sim.robots["sci"], 16.0, 0.0)
    drone = sim.robots["drone"]
    put(drone, 4.0, 0.0)  # hovering on the ray between the lander and the boulder
    drone.z = 1.5
    sim.step(DT)
    assert not sim.wifi(sim.robots["sci"])[1]


def test_a_deployed_wifi_box_extends_coverage(sim: Simulation) -> None:
    rover, box = sim.robots["sci"], sim.boxes["wifi_box"]
    put(rover, 0.0, -25.0)
    assert not sim.wifi(rover)[1]
    box.x, box.y, box.deployed = 0.0, -18.0, True
    assert sim.wifi(rover)[1]


# -- discovery -----------------------------------------------------------------------
def test_fly_over_discovers_the_regions_in_its_area(mars: Simulation) -> None:
    assert run(mars, "drone", "take_off", altitude=8.0).success
    result = run(mars, "drone", "fly_over", area=AREA_A, altitude=8.0, spacing=4.0)
    assert result == RunResult(True, "found RSS A")
    assert [n for n, r in mars.regions.items() if r.discovered] == ["RSS A"]
    assert any("drone discovered RSS A" in line for line in mars.events)


def test_explore_finds_nothing_where_nothing_is(sim: Simulation) -> None:
    area = [{"x": -12, "y": -12}, {"x": -4, "y": -12}, {"x": -4, "y": -4}]
    assert run(sim, "sci", "explore", area=area) == RunResult(True, "found no region")


def test_the_drone_must_take_off_first(sim: Simulation) -> None:
    for skill, params in (("navigate_to", {"target": Pose(5, 5)}), ("fly_over", {"area": AREA_A})):
        result = run(sim, "drone", skill, **params)
        assert result == RunResult(False, "the drone must take off first")


# -- scoring -------------------------------------------------------------------------
def identify_and_deliver(sim: Simulation, *robots: str) -> float:
    discover(sim)
    put(sim.robots["sci"], 12.0, 6.0)
    put(sim.robots["arm"], 16.0, 6.0)
    runs = [runner(sim, r, "identify_stones", position=Pose(14, 8), mode="quick") for r in robots]
    assert all(result.success for result in finish(sim, *runs))
    assert run(sim, "arm", "pick_stone", position=Pose(14, 8)).success
    assert run(sim, "arm", "deposit_at_lander").success
    return sim.score


def test_collaborative_identification_scores_the_maximum(sim: Simulation) -> None:
    assert identify_and_deliver(sim, "sci", "arm") == pytest.approx(1.0)
    assert sim.regions["rss"].identified == LEVEL_COLLABORATIVE


def test_science_rover_alone_scores_a_fraction(sim: Simulation) -> None:
    assert identify_and_deliver(sim, "sci") == pytest.approx(0.5)
    assert sim.regions["rss"].identified == LEVEL_SCIENCE


def test_unidentified_stones_score_the_minimum(sim: Simulation) -> None:
    assert identify_and_deliver(sim) == pytest.approx(0.1)
    assert sim.delivered == 1


def test_the_manipulator_alone_does_not_identify(sim: Simulation) -> None:
    assert identify_and_deliver(sim, "arm") == pytest.approx(0.1)


def test_a_cancelled_identification_does_not_count_as_collaboration(sim: Simulation) -> None:
    discover(sim)
    put(sim.robots["sci"], 12.0, 6.0)
    put(sim.robots["arm"], 16.0, 6.0)
    first = runner(sim, "arm", "identify_stones", position=Pose(14, 8))
    first.update()
    sim.step(DT)
    first.cancel()
    assert run(sim, "sci", "identify_stones", position=Pose(14, 8), mode="quick").success
    assert sim.regions["rss"].identified == LEVEL_SCIENCE


# -- handling --------------------------------------------------------------------------
def test_pick_and_deposit_a_stone(sim: Simulation) -> None:
    discover(sim)
    arm = sim.robots["arm"]
    picked = run(sim, "arm", "pick_stone", position=Pose(14, 8))
    assert picked.success and arm.carrying.startswith("rss stone")
    stone = sim.stones[arm.carrying]
    assert stone.carried_by == "arm" and (stone.x, stone.y) == (arm.x, arm.y)
    assert run(sim, "arm", "deposit_at_lander").success
    assert stone.delivered and not arm.carrying and sim.delivered == 1
    assert sim.score == pytest.approx(0.1)


def test_no_stone_there(sim: Simulation) -> None:
    assert run(sim, "arm", "pick_stone", position=Pose(14, 8)) == RunResult(
        False, "no discovered region at (14.0, 8.0): explore first"
    )
    discover(sim)
    for stone in sim.stones.values():
        stone.delivered = True
    assert run(sim, "arm", "pick_stone", position=Pose(14, 8)) == RunResult(
        False, "no stone left at rss"
    )


def test_the_gripper_already_full(sim: Simulation) -> None:
    discover(sim)
    assert run(sim, "arm", "pick_box", box="wifi_box") == RunResult(True, "holding wifi_box")
    result = run(sim, "arm", "pick_stone", position=Pose(14, 8))
    assert result == RunResult(False, "the gripper already holds wifi_box")
    assert run(sim, "arm", "pick_box", box="wifi_box").text == "the gripper already holds wifi_box"


def test_carry_and_deploy_a_wifi_box(sim: Simulation) -> None:
    arm, box = sim.robots["arm"], sim.boxes["wifi_box"]
    assert run(sim, "arm", "pick_box", box="wifi_box").success
    running = runner(sim, "arm", "place_box", target=Pose(0.0, -15.0))
    for _ in range(50):
        running.update()
        sim.step(DT)
    assert (box.x, box.y) == (arm.x, arm.y) and box.carried_by == "arm"
    assert finish(sim, running)[0] == RunResult(True, "wifi_box deployed")
    assert box.deployed and box.z == pytest.approx(0.25) and not arm.carrying
    assert math.dist((box.x, box.y), (0.0, -15.0)) < 1.5
    assert any("deployed wifi_box" in line for line in sim.events)


def test_only_the_manipulator_handles_things(sim: Simulation) -> None:
    with pytest.raises(SkillFailed, match="a science rover cannot pick_box"):
        sim_skill_for("pick_box", "science_rover")
    with pytest.raises(SkillFailed, match="a science rover cannot take_off"):
        sim_skill_for("take_off", "science_rover")
    with pytest.raises(SkillFailed, match="unknown skill 'dance'"):
        sim_skill_for("dance", "drone")
    assert set(SIM_SKILLS) >= {"navigate_to", "pick_stone", "fly_over"}


# -- running runner -----------------------------------------------------------------------
def test_pause_holds_the_robot_and_resume_goes_on(sim: Simulation) -> None:
    rover = sim.robots["sci"]
    running = runner(sim, "sci", "navigate_to", target=Pose(3.5, -20.0))
    for _ in range(30):
        running.update()
        sim.step(DT)
    running.pause()
    held = (rover.x, rover.y)
    for _ in range(30):
        assert running.update() is None
        sim.step(DT)
    assert (rover.x, rover.y) == held and rover.y < -3.5
    running.resume()
    assert finish(sim, running)[0].success and (rover.x, rover.y) == (3.5, -20.0)


def test_timed_work_does_not_elapse_while_paused(sim: Simulation) -> None:
    discover(sim)
    put(sim.robots["sci"], 12.0, 6.0)
    running = runner(sim, "sci", "identify_stones", position=Pose(14, 8), mode="quick")
    start = sim.time
    for _ in range(20):
        running.update()
        sim.step(DT)
    running.pause()
    for _ in range(200):
        running.update()
        sim.step(DT)
    running.resume()
    assert finish(sim, running)[0].success
    assert sim.time - start >= 10.0 + 20.0 - DT


def test_cancel_stops_the_robot_for_good(sim: Simulation) -> None:
    rover = sim.robots["sci"]
    running = runner(sim, "sci", "navigate_to", target=Pose(3.5, -20.0))
    for _ in range(20):
        running.update()
        sim.step(DT)
    running.cancel()
    assert running.result == RunResult(False, "cancelled")
    where = (rover.x, rover.y)
    sim.step(1.0)
    assert (rover.x, rover.y) == where and running.update() == RunResult(False, "cancelled")


@pytest.mark.parametrize(
    ("skill", "params", "reason"),
    [
        ("take_off", {}, "missing parameter 'altitude'"),
        ("take_off", {"altitude": "high"}, "invalid parameters"),
        ("navigate_to", {"target": {"x": 1.0}}, "invalid parameters"),
        ("identify_stones", {"position": Pose(14, 8), "mode": "slow"}, "mode must be one of"),
    ],
)
def test_malformed_parameters_fail_the_run(
    sim: Simulation, skill: str, params: dict[str, Any], reason: str
) -> None:
    discover(sim)
    robot = "drone" if skill == "take_off" else "sci"
    put(sim.robots["sci"], 12.0, 6.0)
    running = runner(sim, robot, skill, **params)
    result = finish(sim, running)[0]
    assert not result.success and reason in result.text
    assert running.update() == result  # stays failed (it used to turn into a success)
