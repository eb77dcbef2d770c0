"""Marker specs and icon rows to ``visualization_msgs``; feedback poses to plain numbers."""

from __future__ import annotations

import rospy
from geometry_msgs.msg import Point as PointMsg
from geometry_msgs.msg import Pose, Quaternion
from visualization_msgs.msg import (
    InteractiveMarker,
    InteractiveMarkerControl,
    Marker,
    MarkerArray,
    MenuEntry,
)

from rosmc_server.conversions.primitives import color_msg, primitive_msg
from rosmc_server.core.views import geometry as geo
from rosmc_server.core.world.frames import quaternion_from_rpy, yaw_of

from ..core.icons import ICON_TEXT, IconRow, block_centre
from ..core.menus import FlatMenu
from ..core.specs import ControlSpec, MarkerSpec

ICONS_NS = "icons"


def pose_msg(position: geo.Point, yaw: float) -> Pose:
    """A position and heading as ``geometry_msgs/Pose``."""
    return Pose(PointMsg(*position), Quaternion(*quaternion_from_rpy(yaw=yaw)))


def menu_msgs(menu: FlatMenu) -> list[MenuEntry]:
    """A numbered menu as ``visualization_msgs/MenuEntry`` list (feedback by entry id)."""
    return [
        MenuEntry(
            id=e.id, parent_id=e.parent, title=e.title, command="", command_type=MenuEntry.FEEDBACK
        )
        for e in menu.entries
    ]


def control_msg(control: ControlSpec) -> InteractiveMarkerControl:
    """One control of a marker spec."""
    msg = InteractiveMarkerControl()
    msg.name = control.name
    msg.interaction_mode = int(control.interaction)
    msg.orientation = Quaternion(*control.orientation)
    msg.orientation_mode = InteractiveMarkerControl.INHERIT
    msg.always_visible = control.always_visible
    msg.markers = [primitive_msg(p, i) for i, p in enumerate(control.primitives)]
    return msg


def interactive_marker_msg(spec: MarkerSpec) -> InteractiveMarker:
    """A marker spec as ``visualization_msgs/InteractiveMarker``.

    The stamp is zero: rviz then keeps the marker locked to its frame (a robot's
    ``<agent>/base_link``) and follows TF every frame.
    """
    msg = InteractiveMarker()
    msg.header.frame_id = spec.frame
    msg.header.stamp = rospy.Time(0)
    msg.name = spec.name
    msg.description = spec.description
    msg.scale = spec.scale
    msg.pose = pose_msg(spec.position, spec.yaw)
    msg.menu_entries = menu_msgs(spec.menu)
    msg.controls = [control_msg(c) for c in spec.controls]
    return msg


def icon_markers(
    agent: str,
    rows: tuple[IconRow, ...],
    frame: str,
    position: geo.Point,
    base_id: int,
    level: int = 0,
) -> list[Marker]:
    """A robot's status rows as camera-facing text above ``position`` in ``frame``.

    ``level`` lifts the block by whole blocks, so that robots standing close together
    (at the lander, at one region) do not write over each other
    (:func:`~rosmc_rviz_markers.core.icons.icon_levels`). Every row is one marker in its
    own colour, all at the block's centre: its text holds every line of the block, the
    other rows' lines blank, so rviz spaces the lines on screen.
    """
    out = []
    centre = position[2] + block_centre(level, len(rows))
    for index, row in enumerate(rows):
        marker = Marker()
        marker.header.frame_id = frame
        marker.header.stamp = rospy.Time(0)
        marker.frame_locked = True
        marker.ns = f"{ICONS_NS}/{agent}"
        marker.id = base_id + index
        marker.type = Marker.TEXT_VIEW_FACING
        marker.action = Marker.ADD
        marker.pose.position = PointMsg(position[0], position[1], centre)
        marker.pose.orientation.w = 1.0
        marker.scale.z = ICON_TEXT
        marker.color = color_msg(row.color)
        marker.text = "\n".join(r.text if i == index else " " for i, r in enumerate(rows))
        out.append(marker)
    return out


def icon_array(markers: list[Marker]) -> MarkerArray:
    """Icon markers as one array."""
    return MarkerArray(markers=markers)


def pose_numbers(pose: Pose) -> tuple[float, float, float]:
    """x, y and heading of a ``geometry_msgs/Pose`` (NaN passes through for the checks)."""
    q = pose.orientation
    quat = (q.x, q.y, q.z, q.w)
    if not geo.is_finite(*quat) or sum(c * c for c in quat) < 1e-12:
        yaw = float("nan") if not geo.is_finite(*quat) else 0.0
    else:
        yaw = yaw_of(quat)
    return float(pose.position.x), float(pose.position.y), yaw
