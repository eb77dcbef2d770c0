"""The simulator as the site's map provider (rosmc_sim/core/site_map.py); no ROS.

The site it publishes must agree with its own rovers' planner: a target the mission
server accepts for a rover is never one the planner refuses as inside an obstacle or
off the site.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from rosmc_server.core.world.site import Shape, SiteCheck
from rosmc_sim.core.scenario import load_scenario
from rosmc_sim.core.sim import Simulation
from rosmc_sim.core.site_map import site_model

REPO = Path(__file__).resolve().parents[2]
SCENARIOS = sorted((REPO / "rosmc_sim" / "scenarios").glob("*.yaml"))


@pytest.fixture(scope="module", params=SCENARIOS, ids=[p.stem for p in SCENARIOS])
def sim(request: pytest.FixtureRequest) -> Simulation:
    return Simulation(load_scenario(request.param))


def test_the_site_lists_every_obstacle_the_lander_and_the_rovers(sim: Simulation) -> None:
    site = site_model(sim)
    assert site.name == sim.scenario.name and site.bounds == sim.scenario.bounds
    names = [o.name for o in site.obstacles]
    assert names == [*(o.name for o in sim.scenario.obstacles), "lander"]
    lander = site.obstacles[-1]
    assert (lander.shape, lander.size_x) == (Shape.BOX, 2 * sim.scenario.lander_radius)
    rovers = [r.name for r in sim.scenario.robots if r.kind != "drone"]
    assert [r.agent for r in site.robots] == rovers  # no drone
    assert all(r.clearance > sim.clearance for r in site.robots)


def test_every_target_the_site_accepts_for_a_rover_is_free_ground_to_its_planner(
    sim: Simulation,
) -> None:
    site = site_model(sim)
    rover = next(r.name for r in sim.scenario.robots if r.kind == "science_rover")
    x_min, x_max, y_min, y_max = site.bounds
    step = 0.37  # off the planner's 0.5 m grid, so targets fall all over their cells
    accepted = refused = 0
    for i in range(int((x_max - x_min) / step) + 1):
        for j in range(int((y_max - y_min) / step) + 1):
            x, y = x_min + i * step, y_min + j * step
            if site.problem(SiteCheck.REACHABLE_GROUND, rover, x, y):
                refused += 1
                continue
            accepted += 1
            assert sim.grid.free(*sim.grid.cell((x, y))), (x, y)
    assert accepted > 0.8 * (accepted + refused) and refused > 0
