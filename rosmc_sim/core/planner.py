"""Paths around obstacles for the rovers: A* on an occupancy grid, then shortcut.

The grid marks every cell whose centre lies within ``clearance`` of an
obstacle. Paths are searched with 8-connected A*, then shortened by skipping
waypoints wherever the straight segment stays clear, so rovers drive smooth
lines that never cross an obstacle.
"""

from __future__ import annotations

import heapq
import math
from collections.abc import Sequence
from dataclasses import dataclass

from .scenario import Obstacle

Point = tuple[float, float]
_STEPS = [(dx, dy) for dx in (-1, 0, 1) for dy in (-1, 0, 1) if dx or dy]


class NoPath(Exception):
    """The target cannot be reached (inside an obstacle, off the site, or walled in)."""


def obstacle_distance(obstacle: Obstacle, x: float, y: float) -> float:
    """Distance from a point to an obstacle's footprint (0 inside)."""
    return obstacle.footprint().distance(x, y)


@dataclass
class Grid:
    """An occupancy grid over the site."""

    x_min: float
    y_min: float
    resolution: float
    width: int
    height: int
    blocked: list[bytearray]

    @classmethod
    def build(
        cls,
        bounds: tuple[float, float, float, float],
        obstacles: Sequence[Obstacle],
        clearance: float,
        resolution: float = 0.5,
    ) -> Grid:
        """Mark every cell within ``clearance`` of an obstacle (or of the site's edge)."""
        x_min, x_max, y_min, y_max = bounds
        width = math.ceil((x_max - x_min) / resolution)
        height = math.ceil((y_max - y_min) / resolution)
        blocked = [bytearray(height) for _ in range(width)]
        grid = cls(x_min, y_min, resolution, width, height, blocked)
        footprints = [o.footprint() for o in obstacles]
        for i in range(width):
            for j in range(height):
                x, y = grid.center(i, j)
                near_edge = min(x - x_min, x_max - x, y - y_min, y_max - y) < clearance / 2
                if near_edge or any(f.distance(x, y) < clearance for f in footprints):
                    blocked[i][j] = 1
        return grid

    def center(self, i: int, j: int) -> Point:
        """Centre of cell (i, j)."""
        return (self.x_min + (i + 0.5) * self.resolution, self.y_min + (j + 0.5) * self.resolution)

    def cell(self, point: Point) -> tuple[int, int]:
        """The cell a point lies in (clamped to the grid)."""
        i = int((point[0] - self.x_min) / self.resolution)
        j = int((point[1] - self.y_min) / self.resolution)
        return min(max(i, 0), self.width - 1), min(max(j, 0), self.height - 1)

    def free(self, i: int, j: int) -> bool:
        """Whether a cell is on the grid and clear."""
        return 0 <= i < self.width and 0 <= j < self.height and not self.blocked[i][j]

    def segment_clear(self, a: Point, b: Point) -> bool:
        """Whether the straight segment a-b crosses only free cells."""
        length = math.hypot(b[0] - a[0], b[1] - a[1])
        samples = max(1, int(length / (self.resolution / 2)))
        for k in range(samples + 1):
            t = k / samples
            if not self.free(*self.cell((a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])))):
                return False
        return True

    def nearest_free(self, point: Point, max_cells: int = 6) -> tuple[int, int] | None:
        """The free cell nearest to a point, within ``max_cells``."""
        ci, cj = self.cell(point)
        best: tuple[float, tuple[int, int]] | None = None
        for i in range(ci - max_cells, ci + max_cells + 1):
            for j in range(cj - max_cells, cj + max_cells + 1):
                if self.free(i, j):
                    x, y = self.center(i, j)
                    d = math.hypot(x - point[0], y - point[1])
                    if best is None or d < best[0]:
                        best = (d, (i, j))
        return None if best is None else best[1]

    def plan(self, start: Point, goal: Point) -> list[Point]:
        """Waypoints from ``start`` to ``goal`` (goal included); NoPath if none."""
        if self.segment_clear(start, goal):
            return [goal]
        s = self.nearest_free(start)
        g = self.cell(goal)
        if s is None:
            raise NoPath("the robot is stuck inside an obstacle")
        if not self.free(*g):
            raise NoPath(f"({goal[0]:.1f}, {goal[1]:.1f}) lies inside an obstacle or off the site")
        cells = self._astar(s, g)
        points = [start, *(self.center(i, j) for i, j in cells[1:-1]), goal]
        return self._shortcut(points)[1:]

    def _astar(self, start: tuple[int, int], goal: tuple[int, int]) -> list[tuple[int, int]]:
        def h(c: tuple[int, int]) -> float:
            return math.hypot(c[0] - goal[0], c[1] - goal[1])

        frontier: list[tuple[float, float, tuple[int, int]]] = [(h(start), 0.0, start)]
        came: dict[tuple[int, int], tuple[int, int] | None] = {start: None}
        cost = {start: 0.0}
        while frontier:
            _, g_cost, current = heapq.heappop(frontier)
            if current == goal:
                path = [current]
                while (previous := came[path[-1]]) is not None:
                    path.append(previous)
                return path[::-1]
            if g_cost > cost[current]:
                continue
            for dx, dy in _STEPS:
                nxt = (current[0] + dx, current[1] + dy)
                if not self.free(*nxt) or (
                    dx
                    and dy
                    and not (
                        self.free(current[0] + dx, current[1])
                        and self.free(current[0], current[1] + dy)
                    )
                ):
                    continue
                new_cost = g_cost + math.hypot(dx, dy)
                if new_cost < cost.get(nxt, math.inf):
                    cost[nxt] = new_cost
                    came[nxt] = current
                    heapq.heappush(frontier, (new_cost + h(nxt), new_cost, nxt))
        raise NoPath("no path around the obstacles reaches the target")

    def _shortcut(self, points: list[Point]) -> list[Point]:
        out = [points[0]]
        i = 0
        while i < len(points) - 1:
            j = len(points) - 1
            while j > i + 1 and not self.segment_clear(points[i], points[j]):
                j -= 1
            out.append(points[j])
            i = j
        return out
