"""What a click or drag asks of the mission server, worked out before anything is sent.

Pure functions: the node checks feedback with these (a NaN pose, a self-crossing area, a
menu entry for a marker that has gone are refused here with an InvalidRequest, and the
mission is never touched) and then makes the client call they describe.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

from rosmc_server.core.errors import InvalidRequest
from rosmc_server.core.live.edit_history import EditKind
from rosmc_server.core.model.model import TaskMarker
from rosmc_server.core.skills.library import Library
from rosmc_server.core.skills.params import MarkerType, ParamType, Pose, Value
from rosmc_server.core.world import areas

from .menus import DeleteMarker, EditAction, RenameMarker

AHEAD = 4.0  # metres in front of a robot where new task markers appear
AREA_AHEAD = 7.0  # an area's centre in front of the robot (so the robot is outside it)
SIDE_STEP = 2.5  # between several new markers of one skill


@dataclass(frozen=True)
class SkillPlan:
    """An add_skill request: values, and task markers to create and bind first."""

    agent: str
    skill: str
    params: dict[str, Value]
    new_markers: tuple[tuple[str, TaskMarker], ...] = ()
    bindings: tuple[tuple[str, str], ...] = ()


def finite_xy(x: float, y: float, what: str) -> tuple[float, float]:
    """(x, y) if both are finite; InvalidRequest otherwise."""
    if not (math.isfinite(x) and math.isfinite(y)):
        raise InvalidRequest(f"{what} is not a finite position ({x}, {y})")
    return x, y


def new_marker(marker_type: MarkerType, x: float, y: float, yaw: float = 0.0) -> TaskMarker:
    """A task marker the server will name; an area is a square centred at (x, y)."""
    finite_xy(x, y, "the new marker")
    if not math.isfinite(yaw):
        raise InvalidRequest("the new marker's heading is not a finite number")
    if marker_type is MarkerType.AREA:
        corners = areas.square(x, y, yaw)
        return TaskMarker(
            "", MarkerType.AREA, Pose(x, y), tuple(Pose(cx, cy) for cx, cy in corners)
        )
    if marker_type is MarkerType.POSITION:
        yaw = 0.0
    return TaskMarker("", marker_type, Pose(x, y, 0.0, 0.0, 0.0, yaw))


def robot_skill_plan(library: Library, agent: str, skill: str, pose: Pose | None) -> SkillPlan:
    """Adding ``skill`` from ``agent``'s menu: pose parameters take the robot's pose and
    every parameter that takes a task marker gets a new one in front of the robot."""
    spec = library.skill(agent, skill)
    here = pose or Pose()
    cos, sin = math.cos(here.yaw), math.sin(here.yaw)
    params: dict[str, Value] = {}
    markers: list[tuple[str, TaskMarker]] = []
    for param in spec.parameters:
        if param.marker_type is not None:
            ahead = AREA_AHEAD if param.marker_type is MarkerType.AREA else AHEAD
            side = SIDE_STEP * len(markers)
            x = here.x + ahead * cos - side * sin
            y = here.y + ahead * sin + side * cos
            markers.append((param.name, new_marker(param.marker_type, x, y, here.yaw)))
        elif param.type is ParamType.POSE:
            params[param.name] = Pose(here.x, here.y, 0.0, 0.0, 0.0, here.yaw)
    return SkillPlan(agent, skill, params, tuple(markers))


def moved_area(marker: TaskMarker, vertex: int | None, x: float, y: float) -> tuple[Pose, ...]:
    """An area's vertices after dragging vertex ``vertex`` (None: the centre) to (x, y).

    Raises:
        InvalidRequest: Not finite, or the area would cross itself or become too small.
    """
    finite_xy(x, y, f"the drag of '{marker.name}'")
    xy = [(v.x, v.y) for v in marker.vertices]
    if vertex is None:
        moved: Sequence[tuple[float, float]] = areas.translate(
            xy, x - marker.pose.x, y - marker.pose.y
        )
    else:
        if not 0 <= vertex < len(xy):
            raise InvalidRequest(f"area '{marker.name}' has no vertex {vertex}")
        moved = tuple((x, y) if i == vertex else v for i, v in enumerate(xy))
        areas.check_area(moved, f"area '{marker.name}'")
    return tuple(Pose(px, py) for px, py in moved)


def moved_pose(marker: TaskMarker, x: float, y: float, yaw: float) -> Pose:
    """A point or pose marker's new pose (a point keeps heading 0)."""
    finite_xy(x, y, f"the drag of '{marker.name}'")
    if not math.isfinite(yaw):
        raise InvalidRequest(f"the drag of '{marker.name}' has no finite heading")
    if marker.type is MarkerType.POSITION:
        yaw = 0.0
    return Pose(x, y, marker.pose.z, 0.0, 0.0, yaw)


def edit_kind(action: EditAction) -> EditKind:
    """The edit a menu entry makes (what undo can take back)."""
    if isinstance(action, RenameMarker):
        return EditKind.RENAME_MARKER
    if isinstance(action, DeleteMarker):
        return EditKind.DELETE_MARKER
    return EditKind.ADD_SKILL
