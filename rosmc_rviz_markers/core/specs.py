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

from rosmc_server.core.model.model import SkillInstance, TaskMarker
from rosmc_server.core.skills.params import MarkerType
from rosmc_server.core.views import geometry as geo
from rosmc_server.core.views.geometry import Color, Point, Primitive
from rosmc_server.core.world.frames import IDENTITY, Quaternion
from rosmc_server.interface import MAP_FRAME, base_link

from .labels import Label
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

    @property
    def label(self) -> str:
        """The text the marker shows: its description, or the text it draws itself."""
        drawn = (p.text for c in self.controls for p in c.primitives if p.shape is geo.Shape.TEXT)
        return self.description or next(drawn, "")

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
    if robot and geo.top_of(body) < geo.PIN_CLEARANCE:
        body += geo.pin(geo.BODY_COLORS[kind])
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


def describe(marker: TaskMarker, use: MarkerUse, locked: bool) -> str:
    """A task marker's label: its name and how it is used (``goal [blueprint]``)."""
    state = use.label + (", locked" if locked else "")
    return f"{marker.name} [{state}]"


LABEL_TEXT = 0.55  # letter height of a task marker's label
LABEL_Z = 0.35
LABEL_COLOR = Color(0.95, 0.95, 0.97)


def _label_below(marker: TaskMarker, movable: bool) -> float:
    """How far south of its marker's origin a label sits before any decluttering
    (outside the turning ring of a pose marker that can turn)."""
    return geo.TURN_RADIUS + 0.6 if marker.type is MarkerType.POSE and movable else 1.3


def task_label(marker: TaskMarker, text: str, movable: bool = True) -> Label:
    """Where a task marker's label goes (map frame) before :func:`.labels.layout` moves it."""
    y = marker.pose.y - _label_below(marker, movable)
    return Label(marker.name, marker.pose.x, y, LABEL_Z, (text,), LABEL_TEXT)


def _label_primitive(
    marker: TaskMarker, text: str, south: float, yaw: float, movable: bool
) -> Primitive:
    # the marker frame turns with a pose marker's heading; the label must not
    distance = _label_below(marker, movable) + south
    position = (-distance * math.sin(yaw), -distance * math.cos(yaw), LABEL_Z)
    return geo.text(text, position, LABEL_TEXT, LABEL_COLOR)


def task_specs(
    marker: TaskMarker,
    bound: Sequence[SkillInstance],
    use: MarkerUse,
    menu: FlatMenu,
    *,
    locked: bool,
    read_only: bool,
    highlighted: bool = False,
    label_south: float = 0.0,
) -> list[MarkerSpec]:
    """The interactive markers of one task marker: flag/arrow, or polygon + vertices.

    Its label is drawn by the marker itself (no rviz description), ``label_south`` metres
    further south than usual when :func:`.labels.layout` moved it out of the way. A pose
    marker moves by its flag and arrow and turns by a ring well outside them.
    """
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
    yaw = marker.pose.yaw if marker.type is MarkerType.POSE else 0.0
    text = describe(marker, use, locked)
    extra += (_label_primitive(marker, text, label_south, yaw, movable),)
    x, y = marker.pose.x, marker.pose.y
    if marker.type is MarkerType.AREA:
        return _area_specs(marker, color, menu, move_mode, movable, extra)
    visuals = geo.flag(color) + extra
    if marker.type is MarkerType.POSE:
        visuals += (geo.heading_arrow(color),)
    controls = [ControlSpec("flag", move_mode, visuals, UP if movable else IDENTITY)]
    if marker.type is MarkerType.POSE and movable:
        controls.append(ControlSpec("heading", Interaction.ROTATE_AXIS, geo.turn_handle(color)))
    return [
        MarkerSpec(
            task_name(marker.name), MAP_FRAME, (x, y, 0.0), yaw, "", tuple(controls), menu, 2.2
        )
    ]


def _area_specs(
    marker: TaskMarker,
    color: Color,
    menu: FlatMenu,
    move_mode: Interaction,
    movable: bool,
    extra: tuple[Primitive, ...],
) -> list[MarkerSpec]:
    cx, cy = marker.pose.x, marker.pose.y
    relative = [(v.x - cx, v.y - cy) for v in marker.vertices]
    visuals = (*geo.polygon(relative, color), geo.handle(color), *extra)
    centre = MarkerSpec(
        task_name(marker.name),
        MAP_FRAME,
        (cx, cy, 0.0),
        0.0,
        "",
        (ControlSpec("area", move_mode, visuals, UP if movable else IDENTITY),),
        menu,
        scale=2.5,
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
