"""Drawing primitives (:mod:`rosmc_server.core.views.geometry`) as ``visualization_msgs``.

The marker node draws robots, objects and task markers with them in rviz; ``rosmc export``
draws the robots with the same bodies for Foxglove.
"""

from __future__ import annotations

from geometry_msgs.msg import Point as PointMsg
from geometry_msgs.msg import Quaternion
from std_msgs.msg import ColorRGBA
from visualization_msgs.msg import Marker

from rosmc_server.core.views import geometry as geo


def color_msg(color: geo.Color) -> ColorRGBA:
    """A colour as ``std_msgs/ColorRGBA``."""
    return ColorRGBA(color.r, color.g, color.b, color.a)


def primitive_msg(primitive: geo.Primitive, ident: int) -> Marker:
    """One primitive as a ``visualization_msgs/Marker`` (frame and stamp left to the caller)."""
    marker = Marker()
    marker.id = ident
    marker.type = int(primitive.shape)
    marker.action = Marker.ADD
    marker.pose.position = PointMsg(*primitive.position)
    marker.pose.orientation = Quaternion(*primitive.orientation)
    marker.scale.x, marker.scale.y, marker.scale.z = primitive.scale
    marker.color = color_msg(primitive.color)
    marker.points = [PointMsg(*p) for p in primitive.points]
    marker.text = primitive.text
    return marker
