"""The simulator's radio model as a grid (rosmc_sim/core/coverage_model.py)."""

from __future__ import annotations

from pathlib import Path

from rosmc_sim.core.coverage_model import coverage_grid, coverage_prediction
from rosmc_sim.core.scenario import load_scenario
from rosmc_sim.core.sim import Simulation
from rosmc_sim.core.world import World

SCENARIO = Path(__file__).resolve().parents[1] / "data" / "scenario_team.yaml"


def test_the_grid_covers_the_lander_reach_and_a_deployed_box_extends_it() -> None:
    scenario = load_scenario(SCENARIO)
    world = World(scenario)  # pybullet line of sight, as the sim node has it
    sim = Simulation(scenario, world)
    grid = coverage_grid(sim)
    assert (grid.width, grid.height, grid.resolution) == (60, 60, 1.0)
    before = coverage_prediction(sim)
    assert before.at(8.0, 0.0) == sim.signal_at(8.5, 0.5)  # the cell's centre
    assert before.at(8.0, 0.0)[1] and not before.at(17.0, 0.0)[1]  # type: ignore[index]
    far, near = before.at(25.0, 0.0), before.at(3.0, 0.0)
    assert far is not None and near is not None and far[0] < near[0]
    box = sim.boxes["wifi_box"]
    box.x, box.y, box.deployed = 12.0, 0.0, True
    after = coverage_prediction(sim)
    assert after.at(17.0, 0.0)[1]  # type: ignore[index]
    assert sim.wifi_sources() == ((0.0, 0.0), (12.0, 0.0))
    world.close()
