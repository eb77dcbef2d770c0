"""Interactive markers as plain values: one :class:`MarkerSpec` per thing to click or drag.

Names say what a marker is (the node routes feedback by them): ``robot/<agent>``,
``object/<agent>``, ``task/<marker>`` and ``task/<marker>#v<k>`` for an area's vertices.
Two specs that compare equal draw the same, so the node republishes only what changed.
"""

from __future__ import annotations

import enum
import math
import re
from collections.abc import Sequence
from dataclasses import dataclass, field

from rosmc_server.core.frames import IDENTITY, Quaternion
from rosmc_server.core.model import SkillInstance, TaskMarker
from rosmc_server.core.params import MarkerType
from rosmc_server.interface import MAP_FRAME, base_link

from . import geometry as geo
from .geometry import Color, Point, Primitive
from .menus import FlatMenu
from .styling import HIGHLIGHT, LOCK_COLOR, USE_COLORS, MarkerUse

ROBOT = "robot/"
OBJECT = "object/"
TASK = "task/"
_VERTEX = re.compile(r"^(.*)#v(\d+)$")
# Control orientation whose x axis is the map's z: MOVE_PLANE moves in xy, ROTATE_AXIS turns yaw.
UP: Quaternion = (0.0, math.sqrt(0.5), 0.0, math.sqrt(0.5))


class Interaction(enum.IntEnum):
    """Control modes (numbers match ``visualization_msgs/InteractiveMarkerControl``)."""

    NONE = 0
    MENU = 1
    BUTTON = 2
    MOVE_PLANE = 4
    ROTATE_AXIS = 5


@dataclass(frozen=True)
class ControlSpec:
    """One control of an interactive marker: how it reacts and what it draws."""

    name: str
    interaction: Interaction
    primitives: tuple[Primitive, ...] = ()
    orientation: Quaternion = UP
    always_visible: bool = True


@dataclass(frozen=True)
class MarkerSpec:
    """One interactive marker: where, its label, its controls and its menu."""

    name: str
    frame: str
    position: Point
    yaw: float
    description: str
    controls: tuple[ControlSpec, ...]
    menu: FlatMenu = field(default_factory=FlatMenu)
    scale: float = 1.0

    def same_but_pose(self, other: MarkerSpec) -> bool:
        """Whether ``other`` differs from this at most in position and heading."""
        return (
            self.frame == other.frame
            and self.description == other.description
            and self.controls == other.controls
            and self.menu == other.menu
            and self.scale == other.scale
        )


@dataclass(frozen=True)
class Parsed:
    """What a marker name refers to: ``kind`` robot/object/task, the name, a vertex index."""

    kind: str
    name: str
    vertex: int | None = None


def robot_name(agent: str) -> str:
    """The interactive marker name of a robot."""
    return ROBOT + agent


def object_name(agent: str) -> str:
    """The interactive marker name of a static agent."""
    return OBJECT + agent


def task_name(marker: str) -> str:
    """The interactive marker name of a task marker (an area's centre handle)."""
    return TASK + marker


def vertex_name(marker: str, index: int) -> str:
    """The interactive marker name of vertex ``index`` of area ``marker``."""
    return f"{TASK}{marker}#v{index}"


def parse_name(name: str) -> Parsed | None:
    """What an interactive marker name refers to (None: not one of ours)."""
    for prefix, kind in ((ROBOT, "robot"), (OBJECT, "object")):
        if name.startswith(prefix) and len(name) > len(prefix):
            return Parsed(kind, name[len(prefix) :])
    if name.startswith(TASK) and len(name) > len(TASK):
        rest = name[len(TASK) :]
        match = _VERTEX.match(rest)
        if match:
            return Parsed("task", match.group(1), int(match.group(2)))
        return Parsed("task", rest)
    return None


# -- builders ------------------------------------------------------------------------------------
def agent_spec(
    agent: str,
    kind: geo.BodyKind,
    menu: FlatMenu,
    *,
    robot: bool,
    highlighted: bool = False,
    frame: str | None = None,
    position: Point = (0.0, 0.0, 0.0),
    yaw: float = 0.0,
) -> MarkerSpec:
    """A robot or static agent: its body, clickable for its menu, following its TF frame."""
    body = geo.agent_body(kind)
    if highlighted:
        body = (*body, geo.ring(HIGHLIGHT, 1.8 if robot else 0.7))
    mode = Interaction.MENU if menu.entries else Interaction.NONE
    return MarkerSpec(
        name=(robot_name if robot else object_name)(agent),
        frame=frame or base_link(agent),
        position=position,
        yaw=yaw,
        description="" if robot else agent,  # a robot's status icons start with its name
        controls=(ControlSpec("body", mode, body, IDENTITY),),
        menu=menu,
        scale=3.0 if robot else 1.5,
    )


def _describe(marker: TaskMarker, use: MarkerUse, locked: bool) -> str:
    state = use.label + (", locked" if locked else "")
    return f"{marker.name} [{state}]"


def task_specs(
    marker: TaskMarker,
    bound: Sequence[SkillInstance],
    use: MarkerUse,
    menu: FlatMenu,
    *,
    locked: bool,
    read_only: bool,
    highlighted: bool = False,
) -> list[MarkerSpec]:
    """The interactive markers of one task marker: flag/arrow, or polygon + vertices."""
    del bound  # the colour and menu already say what the bound skills mean
    color = USE_COLORS[use]
    movable = not locked and not read_only
    extra: tuple[Primitive, ...] = ()
    if highlighted:
        extra += (geo.ring(HIGHLIGHT, 1.0),)
    if locked:
        extra += (geo.ring(LOCK_COLOR, 0.6, width=0.08),)
    menu_mode = Interaction.MENU if menu.entries else Interaction.NONE
    move_mode = Interaction.MOVE_PLANE if movable else menu_mode
    description = _describe(marker, use, locked)
    x, y = marker.pose.x, marker.pose.y
    if marker.type is MarkerType.AREA:
        return _area_specs(marker, color, menu, move_mode, movable, extra, description)
    visuals = geo.flag(color) + extra
    controls = [ControlSpec("flag", move_mode, visuals, UP if movable else IDENTITY)]
    yaw = 0.0
    if marker.type is MarkerType.POSE:
        yaw = marker.pose.yaw
        arrow = geo.heading_arrow(color)
        if movable:
            ring = geo.ring(color.with_alpha(0.9), 2.3, z=0.06, width=0.12)
            controls.append(ControlSpec("heading", Interaction.ROTATE_AXIS, (arrow, ring)))
        else:
            controls.append(ControlSpec("heading", menu_mode, (arrow,), IDENTITY))
    return [
        MarkerSpec(
            task_name(marker.name),
            MAP_FRAME,
            (x, y, 0.0),
            yaw,
            description,
            tuple(controls),
            menu,
            scale=2.2,  # rviz writes the label 1.4 x scale up: just above the flag
        )
    ]


def _area_specs(
    marker: TaskMarker,
    color: Color,
    menu: FlatMenu,
    move_mode: Interaction,
    movable: bool,
    extra: tuple[Primitive, ...],
    description: str,
) -> list[MarkerSpec]:
    cx, cy = marker.pose.x, marker.pose.y
    relative = [(v.x - cx, v.y - cy) for v in marker.vertices]
    visuals = (*geo.polygon(relative, color), geo.handle(color), *extra)
    centre = MarkerSpec(
        task_name(marker.name),
        MAP_FRAME,
        (cx, cy, 0.0),
        0.0,
        description,
        (ControlSpec("area", move_mode, visuals, UP if movable else IDENTITY),),
        menu,
        scale=2.5,  # the label stays low, under what flies over the area
    )
    specs = [centre]
    if movable:
        for index, vertex in enumerate(marker.vertices):
            specs.append(
                MarkerSpec(
                    vertex_name(marker.name, index),
                    MAP_FRAME,
                    (vertex.x, vertex.y, 0.0),
                    0.0,
                    "",
                    (ControlSpec("vertex", Interaction.MOVE_PLANE, (geo.handle(color, 0.5),)),),
                    scale=1.0,
                )
            )
    return specs
