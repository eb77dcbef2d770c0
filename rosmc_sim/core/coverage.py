"""How much of each region for sampling stones the ground's Wi-Fi reaches, by the radio model.

The same model the simulator runs (:meth:`Simulation.signal_at`: range and line of sight
through the obstacles' bodies), sampled on a grid over each region's disc at a rover's
antenna height, with the boxes where they are (none deployed at the start). The site table of
docs/operator-guide.md states these figures and a test compares them.
"""

from __future__ import annotations

import math

from .scenario import Region
from .sim import Simulation

ROVER_ANTENNA = 0.5  # m above the ground, as for a rover standing there


def region_coverage(sim: Simulation, region: Region, step: float = 0.5) -> float:
    """The fraction (0..1) of ``region``'s disc where a rover would be in coverage."""
    covered = total = 0
    cells = math.ceil(region.radius / step)
    for i in range(-cells, cells + 1):
        for j in range(-cells, cells + 1):
            dx, dy = i * step, j * step
            if math.hypot(dx, dy) > region.radius:
                continue
            total += 1
            covered += sim.signal_at(region.x + dx, region.y + dy, ROVER_ANTENNA)[1]
    return covered / total if total else 0.0


def coverage_by_region(sim: Simulation) -> dict[str, float]:
    """Every region's covered fraction, by name, in the scenario's order."""
    return {region.name: region_coverage(sim, region) for region in sim.scenario.regions}
