"""The simulated site as a map provider describes it, for the mission server's target checks.

The rovers' planner marks a grid cell blocked when its centre lies within the clearance of
an obstacle (or within half of it from the site's edge), and refuses a target whose cell is
blocked. A target can lie up to half a cell's diagonal from its cell's centre, so the
distances published here add that: a target the mission server accepts never lies in a
blocked cell. The drone flies over obstacles and is not listed.
"""

from __future__ import annotations

import math

from rosmc_server.core.world.site import GroundRobot, SiteModel

from .sim import Simulation


def site_model(sim: Simulation) -> SiteModel:
    """The site of ``sim``: its bounds, obstacle footprints (the lander too) and rovers."""
    cell = sim.grid.resolution * math.sqrt(2) / 2
    rovers = tuple(
        GroundRobot(robot.name, robot.kind, sim.clearance + cell, sim.clearance / 2 + cell)
        for robot in sim.robots.values()
        if robot.kind != "drone"
    )
    obstacles = tuple(o.footprint() for o in sim.ground_obstacles)
    return SiteModel(sim.scenario.name, sim.scenario.bounds, obstacles, rovers)
