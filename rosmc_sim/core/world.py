"""The pybullet side of the simulation: bodies, kinematic poses and line of sight.

Physics accuracy is not the point: bodies are moved kinematically, but every
robot, box, stone, obstacle and the lander is a pybullet body, carried objects
follow their carrier, and Wi-Fi line of sight is a pybullet ray test.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import pybullet as pb

from rosmc_server.core.views.vocabulary import PALETTE

from .scenario import Scenario

ROBOT_SIZE = {
    "drone": (0.7, 0.7, 0.15),
    "science_rover": (1.3, 0.9, 0.6),
    "manipulator_rover": (1.4, 1.0, 0.6),
}
BOX_SIZE = 0.5
STONE_RADIUS = 0.15
# Collision groups: Bullet puts static bodies in group 2 (mask: all but 2); obstacles also get
# their own bit, so a line-of-sight ray sees only them (not a robot or a box in between).
_STATIC_GROUP = 2
_OBSTACLE_GROUP = 64


@dataclass(frozen=True)
class Placement:
    """Where a body is: position and heading."""

    x: float
    y: float
    z: float
    yaw: float = 0.0


class World:
    """A pybullet world built from a scenario (DIRECT by default, GUI on request)."""

    def __init__(self, scenario: Scenario, gui: bool = False) -> None:
        self.client = pb.connect(pb.GUI if gui else pb.DIRECT)
        # The GUI redraws after every body added (seconds each with software GL); draw
        # once everything is built, i.e. from the first step on.
        self._render_pending = gui
        if gui:
            pb.configureDebugVisualizer(pb.COV_ENABLE_RENDERING, 0, physicsClientId=self.client)
        self._bodies: dict[str, int] = {}
        # Where each body was last put: most bodies stand still most steps, and
        # re-placing them is a third of a step's cost with 20 robots.
        self._placed: dict[str, Placement] = {}
        self._obstacle_ids: set[int] = set()
        x_min, x_max, y_min, y_max = scenario.bounds
        half = ((x_max - x_min) / 2, (y_max - y_min) / 2, 0.05)
        self._add(
            "ground", "ground", pb.GEOM_BOX, half, ((x_min + x_max) / 2, (y_min + y_max) / 2, -0.05)
        )
        for obstacle in scenario.obstacles:
            if obstacle.shape == "cylinder":
                body = self._add(
                    obstacle.name,
                    "obstacles",
                    pb.GEOM_CYLINDER,
                    (obstacle.radius, obstacle.height),
                    (obstacle.x, obstacle.y, obstacle.height / 2),
                )
            else:
                body = self._add(
                    obstacle.name,
                    "obstacles",
                    pb.GEOM_BOX,
                    (obstacle.size_x / 2, obstacle.size_y / 2, obstacle.height / 2),
                    (obstacle.x, obstacle.y, obstacle.height / 2),
                    obstacle.yaw,
                )
            self._obstacle_ids.add(body)
            pb.setCollisionFilterGroupMask(
                body,
                -1,
                _STATIC_GROUP | _OBSTACLE_GROUP,
                -1 ^ _STATIC_GROUP,
                physicsClientId=self.client,
            )
        self._add(
            "lander", "lander", pb.GEOM_BOX, (scenario.lander_radius,) * 2 + (0.6,), (0, 0, 0.6)
        )
        for robot in scenario.robots:
            size = ROBOT_SIZE[robot.kind]
            self._add(
                robot.name,
                robot.kind,
                pb.GEOM_BOX,
                tuple(s / 2 for s in size),
                (robot.x, robot.y, size[2] / 2),
                robot.yaw,
            )
        for box in scenario.boxes:
            self._add(box.name, "boxes", pb.GEOM_BOX, (BOX_SIZE / 2,) * 3, (box.x, box.y, 1.45))

    def _add(
        self,
        name: str,
        kind: str,
        shape: int,
        size: tuple[float, ...],
        position: tuple[float, float, float],
        yaw: float = 0.0,
    ) -> int:
        if shape == pb.GEOM_BOX:
            collision = pb.createCollisionShape(
                shape, halfExtents=size, physicsClientId=self.client
            )
            visual = pb.createVisualShape(
                shape, halfExtents=size, rgbaColor=PALETTE[kind], physicsClientId=self.client
            )
        elif shape == pb.GEOM_CYLINDER:
            collision = pb.createCollisionShape(
                shape, radius=size[0], height=size[1], physicsClientId=self.client
            )
            visual = pb.createVisualShape(
                shape,
                radius=size[0],
                length=size[1],
                rgbaColor=PALETTE[kind],
                physicsClientId=self.client,
            )
        else:
            collision = pb.createCollisionShape(shape, radius=size[0], physicsClientId=self.client)
            visual = pb.createVisualShape(
                shape, radius=size[0], rgbaColor=PALETTE[kind], physicsClientId=self.client
            )
        body: int = pb.createMultiBody(
            0,
            collision,
            visual,
            position,
            pb.getQuaternionFromEuler((0, 0, yaw)),
            physicsClientId=self.client,
        )
        self._bodies[name] = body
        return body

    def add_stone(self, name: str, x: float, y: float) -> None:
        """A stone lying on the ground."""
        self._add(name, "stones", pb.GEOM_SPHERE, (STONE_RADIUS,), (x, y, STONE_RADIUS))

    def place(self, name: str, where: Placement) -> None:
        """Move a body (kinematically); a body already there is left alone."""
        if self._placed.get(name) == where:
            return
        self._placed[name] = where
        pb.resetBasePositionAndOrientation(
            self._bodies[name],
            (where.x, where.y, where.z),
            pb.getQuaternionFromEuler((0, 0, where.yaw)),
            physicsClientId=self.client,
        )

    def placement(self, name: str) -> Placement:
        """Where a body is."""
        position, orientation = pb.getBasePositionAndOrientation(
            self._bodies[name], physicsClientId=self.client
        )
        yaw = pb.getEulerFromQuaternion(orientation)[2]
        return Placement(position[0], position[1], position[2], yaw)

    def line_of_sight(self, a: tuple[float, float, float], b: tuple[float, float, float]) -> bool:
        """Whether no obstacle blocks the straight line between two points."""
        hit = pb.rayTest(a, b, collisionFilterMask=_OBSTACLE_GROUP, physicsClientId=self.client)[0]
        return hit[0] not in self._obstacle_ids

    def step(self) -> None:
        """Advance pybullet (kinematic bodies need no dynamics; keeps the GUI live)."""
        if self._render_pending:
            self._render_pending = False
            pb.configureDebugVisualizer(pb.COV_ENABLE_RENDERING, 1, physicsClientId=self.client)
        pb.stepSimulation(physicsClientId=self.client)

    def close(self) -> None:
        """Disconnect from pybullet."""
        if pb.isConnected(self.client):
            pb.disconnect(self.client)


def heading(dx: float, dy: float) -> float:
    """The yaw of a direction."""
    return math.atan2(dy, dx)
