"""The simulator's radio model over the whole site, as a grid the ground can draw.

Each cell holds the signal and coverage a robot standing at the cell's centre would have
(:meth:`Simulation.signal_at`: the lander's access point, deployed Wi-Fi boxes, obstacles
in the way). The grid is as fine as :data:`RESOLUTION`, coarser on sites so large that it
would exceed :data:`MAX_CELLS` cells.
"""

from __future__ import annotations

import math

from rosmc_server.core.robots.radio_map import GridSpec, Prediction

from .sim import Simulation

RESOLUTION = 1.0
MAX_CELLS = 10_000


def coverage_grid(sim: Simulation) -> GridSpec:
    """The grid over the site's bounds."""
    x_min, x_max, y_min, y_max = sim.scenario.bounds
    area = (x_max - x_min) * (y_max - y_min)
    resolution = max(RESOLUTION, math.sqrt(area / MAX_CELLS))
    width = max(1, int((x_max - x_min) / resolution))
    height = max(1, int((y_max - y_min) / resolution))
    return GridSpec(x_min + resolution / 2, y_min + resolution / 2, resolution, width, height)


def coverage_prediction(sim: Simulation) -> Prediction:
    """The radio model's signal and coverage in every cell of :func:`coverage_grid`."""
    grid = coverage_grid(sim)
    signal: list[float] = []
    covered: list[bool] = []
    for index in range(grid.width * grid.height):
        dbm, reached = sim.signal_at(*grid.centre(index))
        signal.append(dbm)
        covered.append(reached)
    return Prediction(grid, tuple(signal), tuple(covered))
