"""Shapes as plain values: what rviz draws, described like ``visualization_msgs/Marker``.

A :class:`Primitive` is one shape (cube, sphere, cylinder, arrow, lines, triangles,
camera-facing text) relative to its interactive marker's pose. The ROS layer turns each
into a ``visualization_msgs/Marker`` field by field; nothing here knows rospy.
Orientation math and frame names are the shared ones (:mod:`rosmc_server.core.world.frames`,
:mod:`rosmc_server.interface`).
Robot bodies are recognisable at the default zoom: a drone with four rotors, rovers with
six wheels and a camera mast, the manipulator with its arm.
"""

from __future__ import annotations

import enum
import math
from collections.abc import Sequence
from dataclasses import dataclass, replace

from ..world.frames import IDENTITY, Quaternion
from ..world.frames import quaternion_from_rpy as quaternion
from .vocabulary import PALETTE

Point = tuple[float, float, float]
CHAR_WIDTH = 0.62  # a character's width in letter heights (rviz's text font, generously)


@dataclass(frozen=True)
class Color:
    """An RGBA colour, each channel 0..1."""

    r: float
    g: float
    b: float
    a: float = 1.0

    def with_alpha(self, alpha: float) -> Color:
        """The same colour with another opacity."""
        return Color(self.r, self.g, self.b, alpha)

    def lighter(self, amount: float = 0.35) -> Color:
        """The colour mixed with white by ``amount`` (0..1)."""

        def mix(c: float) -> float:
            return c + (1.0 - c) * amount

        return Color(mix(self.r), mix(self.g), mix(self.b), self.a)


class Shape(enum.IntEnum):
    """Marker shapes (numbers match ``visualization_msgs/Marker`` types)."""

    ARROW = 0
    CUBE = 1
    SPHERE = 2
    CYLINDER = 3
    LINE_STRIP = 4
    LINE_LIST = 5
    TEXT = 9
    TRIANGLE_LIST = 11


@dataclass(frozen=True)
class Primitive:
    """One shape relative to its marker's pose (see ``visualization_msgs/Marker``)."""

    shape: Shape
    color: Color
    position: Point = (0.0, 0.0, 0.0)
    scale: Point = (1.0, 1.0, 1.0)
    orientation: Quaternion = IDENTITY
    points: tuple[Point, ...] = ()
    text: str = ""


def is_finite(*values: float) -> bool:
    """Every value is a finite number."""
    return all(math.isfinite(v) for v in values)


class BodyKind(enum.Enum):
    """How an agent looks in rviz, chosen from its library model name."""

    DRONE = "drone"
    SCIENCE_ROVER = "science_rover"
    MANIPULATOR_ROVER = "manipulator_rover"
    ROVER = "rover"
    LANDER = "lander"
    PAYLOAD_BOX = "payload_box"
    GENERIC = "generic"


def body_kind(model: str) -> BodyKind:
    """The body an agent of library model ``model`` gets (by the words in its name)."""
    name = model.lower()
    if "drone" in name or "uav" in name or "copter" in name:
        return BodyKind.DRONE
    if "manipulator" in name or "arm" in name:
        return BodyKind.MANIPULATOR_ROVER
    if "science" in name:
        return BodyKind.SCIENCE_ROVER
    if "rover" in name:
        return BodyKind.ROVER
    if "lander" in name:
        return BodyKind.LANDER
    if "box" in name or "payload" in name:
        return BodyKind.PAYLOAD_BOX
    return BodyKind.GENERIC


# Body colours per kind: the palette the simulator paints its bodies with.
_PALETTE_NAME = {
    BodyKind.DRONE: "drone",
    BodyKind.SCIENCE_ROVER: "science_rover",
    BodyKind.MANIPULATOR_ROVER: "manipulator_rover",
    BodyKind.ROVER: "rover",
    BodyKind.LANDER: "lander",
    BodyKind.PAYLOAD_BOX: "boxes",
    BodyKind.GENERIC: "robot",
}
BODY_COLORS = {kind: Color(*PALETTE[name]) for kind, name in _PALETTE_NAME.items()}
DARK = Color(0.12, 0.12, 0.14)
METAL = Color(0.55, 0.57, 0.60)
WHEEL_ROLL = quaternion(roll=math.pi / 2)


def _box(color: Color, x: float, y: float, z: float, sx: float, sy: float, sz: float) -> Primitive:
    return Primitive(Shape.CUBE, color, (x, y, z), (sx, sy, sz))


def _wheels(xs: Sequence[float], half_track: float, radius: float) -> list[Primitive]:
    return [
        Primitive(
            Shape.CYLINDER,
            DARK,
            (x, side * half_track, radius),
            (2 * radius,) * 2 + (0.14,),
            WHEEL_ROLL,
        )
        for x in xs
        for side in (-1.0, 1.0)
    ]


def drone_body(color: Color) -> tuple[Primitive, ...]:
    """A quadcopter: body, two crossed arms, four rotor discs, skids (frame at the bottom)."""
    parts = [
        _box(color, 0.0, 0.0, 0.12, 0.32, 0.32, 0.12),
        Primitive(
            Shape.CUBE, METAL, (0.0, 0.0, 0.14), (0.95, 0.05, 0.04), quaternion(yaw=math.pi / 4)
        ),
        Primitive(
            Shape.CUBE, METAL, (0.0, 0.0, 0.14), (0.95, 0.05, 0.04), quaternion(yaw=-math.pi / 4)
        ),
        _box(DARK, 0.0, -0.12, 0.02, 0.45, 0.03, 0.03),
        _box(DARK, 0.0, 0.12, 0.02, 0.45, 0.03, 0.03),
        _box(Color(1.0, 1.0, 1.0), 0.17, 0.0, 0.12, 0.04, 0.12, 0.06),  # front light
    ]
    arm = 0.95 / 2 * math.cos(math.pi / 4)
    for sx in (-1.0, 1.0):
        for sy in (-1.0, 1.0):
            parts.append(
                Primitive(
                    Shape.CYLINDER,
                    color.lighter(0.5).with_alpha(0.8),
                    (sx * arm, sy * arm, 0.18),
                    (0.36, 0.36, 0.02),
                )
            )
    return tuple(parts)


def rover_body(color: Color, science: bool = False) -> tuple[Primitive, ...]:
    """A six-wheeled rover; the science rover carries a camera mast."""
    parts = [
        _box(color, 0.0, 0.0, 0.38, 1.3, 0.75, 0.26),
        _box(color.lighter(0.3), -0.2, 0.0, 0.55, 0.6, 0.55, 0.08),  # solar deck
        *_wheels((-0.45, 0.0, 0.45), 0.47, 0.2),
    ]
    if science:
        parts += [
            Primitive(Shape.CYLINDER, METAL, (0.45, 0.0, 0.75), (0.08, 0.08, 0.5)),
            _box(DARK, 0.47, 0.0, 1.02, 0.14, 0.32, 0.12),  # camera head
            Primitive(Shape.SPHERE, Color(0.3, 0.8, 1.0), (0.55, 0.09, 1.02), (0.07, 0.07, 0.07)),
            Primitive(Shape.SPHERE, Color(0.3, 0.8, 1.0), (0.55, -0.09, 1.02), (0.07, 0.07, 0.07)),
        ]
    return tuple(parts)


def manipulator_body(color: Color) -> tuple[Primitive, ...]:
    """A rover with a two-link arm and a gripper reaching forward."""
    shoulder = (0.35, 0.0, 0.62)
    return (
        _box(color, 0.0, 0.0, 0.38, 1.4, 0.8, 0.26),
        *_wheels((-0.45, 0.0, 0.45), 0.5, 0.2),
        Primitive(Shape.CYLINDER, METAL, shoulder, (0.2, 0.2, 0.22)),
        # upper arm tilted up and back, forearm reaching forward and down
        Primitive(Shape.CUBE, METAL, (0.25, 0.0, 0.95), (0.08, 0.08, 0.6), quaternion(pitch=-0.5)),
        Primitive(Shape.CUBE, METAL, (0.55, 0.0, 1.1), (0.6, 0.07, 0.07), quaternion(pitch=0.45)),
        _box(DARK, 0.86, 0.05, 0.92, 0.12, 0.03, 0.14),
        _box(DARK, 0.86, -0.05, 0.92, 0.12, 0.03, 0.14),
    )


def generic_body(color: Color) -> tuple[Primitive, ...]:
    """A plain box with a nose, for agent models without a known body."""
    return (
        _box(color, 0.0, 0.0, 0.3, 0.8, 0.6, 0.6),
        Primitive(Shape.ARROW, DARK, (0.4, 0.0, 0.3), (0.3, 0.08, 0.08)),
    )


LANDER_SHELL_HEIGHT = 1.3


def static_shell(kind: BodyKind) -> tuple[Primitive, ...]:
    """A translucent clickable shell around a static agent (the world draws the object)."""
    color = BODY_COLORS[kind].with_alpha(0.3)
    if kind is BodyKind.LANDER:
        height = LANDER_SHELL_HEIGHT
        return (Primitive(Shape.CYLINDER, color, (0.0, 0.0, height / 2), (4.3, 4.3, height)),)
    return (_box(color, 0.0, 0.0, 0.27, 0.62, 0.62, 0.62),)


# Robots are drawn larger than life, so that an operator tells them apart at the default
# view of the whole work area (the drone the most: it is the smallest and flies highest).
ROBOT_SCALE = {BodyKind.DRONE: 2.2}
DEFAULT_ROBOT_SCALE = 1.6


def scaled(parts: Sequence[Primitive], factor: float) -> tuple[Primitive, ...]:
    """``parts`` grown by ``factor`` about the frame origin (positions, sizes, points)."""

    def grow(p: Point) -> Point:
        return (p[0] * factor, p[1] * factor, p[2] * factor)

    out = []
    for part in parts:
        scale = part.scale
        if part.shape not in (Shape.LINE_STRIP, Shape.LINE_LIST, Shape.TEXT):
            scale = grow(scale)  # a line's width and a text's height stay as they are
        points = tuple(grow(p) for p in part.points)
        out.append(replace(part, position=grow(part.position), scale=scale, points=points))
    return tuple(out)


def top_of(parts: Sequence[Primitive]) -> float:
    """The highest point of ``parts`` (boxes, cylinders and spheres by their scale)."""
    return max((p.position[2] + p.scale[2] / 2 for p in parts), default=0.0)


# A robot lower than the lander (the drone resting on it) would hide inside the lander's
# shell and the world's lander: it gets a pin above, clickable wherever the robot stands.
# The pin's flat head is seen well from the shipped views (they look steeply down) and
# stays under the robot's status block (icons.ICON_BASE).
PIN_CLEARANCE = LANDER_SHELL_HEIGHT + 0.1
PIN_STEM = 0.22
PIN_HEAD = (0.7, 0.7, 0.3)
PIN_CENTRE = PIN_CLEARANCE + PIN_STEM + PIN_HEAD[2] / 2  # of the head, above the robot


def pin(color: Color) -> tuple[Primitive, ...]:
    """A map pin over a robot: a flat head on a cone pointing down at the robot."""
    down = quaternion(pitch=math.pi / 2)
    stem_top = PIN_CLEARANCE + PIN_STEM
    return (
        Primitive(Shape.ARROW, color, (0.0, 0.0, stem_top), (PIN_STEM, 0.3, 0.3), down),
        Primitive(Shape.SPHERE, color, (0.0, 0.0, PIN_CENTRE), PIN_HEAD),
    )


def agent_body(kind: BodyKind) -> tuple[Primitive, ...]:
    """The body of a robot or static agent of ``kind`` (frame at the bottom, x forward).

    Robots are scaled by :data:`ROBOT_SCALE`; static agents' shells fit the world's objects.
    """
    color = BODY_COLORS[kind]
    if kind in (BodyKind.LANDER, BodyKind.PAYLOAD_BOX):
        return static_shell(kind)
    if kind is BodyKind.DRONE:
        body = drone_body(color)
    elif kind is BodyKind.SCIENCE_ROVER:
        body = rover_body(color, science=True)
    elif kind is BodyKind.ROVER:
        body = rover_body(color)
    elif kind is BodyKind.MANIPULATOR_ROVER:
        body = manipulator_body(color)
    else:
        body = generic_body(color)
    return scaled(body, ROBOT_SCALE.get(kind, DEFAULT_ROBOT_SCALE))


# -- task markers ------------------------------------------------------------------------------
FLAG_HEIGHT = 2.2
# rviz picks what is drawn: the flag's whole footprint is there to be grabbed. A ground disc
# of 1.2 m and a 10 cm pole were hard to hit from the shipped views (a few pixels wide).
FLAG_DISC = 2.0  # diameter of the ground disc (m)
FLAG_POLE = 0.22  # thickness of the pole (m)
FLAG_CLOTH = (1.3, 0.9)  # length and height of the cloth (m)


def flag(color: Color) -> tuple[Primitive, ...]:
    """A flag: pole, cloth and a ground disc (its foot is at the marker's origin).

    The cloth is a thin box (lit from both sides; a triangle list has no normals in rviz
    and shows black).
    """
    length, height = FLAG_CLOTH
    pole = (FLAG_POLE, FLAG_POLE, FLAG_HEIGHT)
    return (
        Primitive(Shape.CYLINDER, DARK, (0.0, 0.0, FLAG_HEIGHT / 2), pole),
        _box(
            color.with_alpha(1.0),
            length / 2 + 0.05,
            0.0,
            FLAG_HEIGHT - height / 2,
            length,
            0.06,
            height,
        ),
        Primitive(Shape.CYLINDER, color, (0.0, 0.0, 0.02), (FLAG_DISC, FLAG_DISC, 0.04)),
    )


def heading_arrow(color: Color) -> Primitive:
    """An arrow along the marker's x axis (its heading), lying on the ground."""
    return Primitive(Shape.ARROW, color.with_alpha(1.0), (0.0, 0.0, 0.1), (2.2, 0.3, 0.3))


# The turning ring of a pose marker lies well outside the flag and the heading arrow
# (2.2 m), so that grabbing the marker near its arrow moves it and only the ring turns it.
TURN_RADIUS = 3.4


def turn_handle(color: Color) -> tuple[Primitive, ...]:
    """The ring that turns a pose marker, with a knob where the heading points."""
    solid = color.with_alpha(1.0)
    return (
        ring(solid, TURN_RADIUS, z=0.08, width=0.3),
        Primitive(Shape.SPHERE, solid, (TURN_RADIUS, 0.0, 0.15), (0.7, 0.7, 0.3)),
    )


def text(words: str, position: Point, height: float, color: Color) -> Primitive:
    """Camera-facing text centred at ``position`` (``height``: the letters')."""
    return Primitive(Shape.TEXT, color, position, (0.0, 0.0, height), text=words)


def ring(color: Color, radius: float, z: float = 0.05, width: float = 0.12) -> Primitive:
    """A closed circle on the ground (selection highlight)."""
    steps = 36
    points = tuple(
        (radius * math.cos(2 * math.pi * i / steps), radius * math.sin(2 * math.pi * i / steps), z)
        for i in range(steps + 1)
    )
    return Primitive(Shape.LINE_STRIP, color, scale=(width, 0.0, 0.0), points=points)


def polygon(
    vertices: Sequence[tuple[float, float]], color: Color, z: float = 0.04
) -> tuple[Primitive, ...]:
    """A filled polygon with a bold outline; ``vertices`` relative to the marker origin."""
    from ..world.areas import triangulate  # areas imports nothing from here

    outline = tuple((x, y, z + 0.01) for x, y in (*vertices, vertices[0]))
    triangles = tuple((x, y, z) for tri in triangulate(vertices) for x, y in tri)
    return (
        Primitive(Shape.TRIANGLE_LIST, color, points=triangles),
        Primitive(Shape.LINE_STRIP, color.with_alpha(1.0), scale=(0.12, 0.0, 0.0), points=outline),
    )


def handle(color: Color, size: float = 0.45) -> Primitive:
    """A small sphere to grab (area centre and vertices)."""
    return Primitive(Shape.SPHERE, color.with_alpha(1.0), (0.0, 0.0, size / 2), (size,) * 3)
