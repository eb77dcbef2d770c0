"""Orientation math for poses in the map frame: quaternions and roll, pitch, yaw.

Pure Python, so the simulator, the marker servers and the GUIs share one version
without importing each other (or ROS). A quaternion is an ``(x, y, z, w)`` tuple,
the field order of ``geometry_msgs/Quaternion``; angles are radians, applied in
z-y-x order (yaw, then pitch, then roll), as in ROS and :class:`~.params.Pose`.
The frame *names* (``map``, ``<agent>/base_link``) are graph names and live in
:mod:`rosmc_server.interface`.
"""

from __future__ import annotations

import math

from ..errors import InvalidRequest

Quaternion = tuple[float, float, float, float]
"""A rotation as ``(x, y, z, w)``."""

IDENTITY: Quaternion = (0.0, 0.0, 0.0, 1.0)
"""No rotation."""


def quaternion_from_rpy(roll: float = 0.0, pitch: float = 0.0, yaw: float = 0.0) -> Quaternion:
    """The rotation of ``roll``, ``pitch`` and ``yaw`` (z-y-x) as a unit quaternion."""
    cr, sr = math.cos(roll / 2), math.sin(roll / 2)
    cp, sp = math.cos(pitch / 2), math.sin(pitch / 2)
    cy, sy = math.cos(yaw / 2), math.sin(yaw / 2)
    return (
        sr * cp * cy - cr * sp * sy,
        cr * sp * cy + sr * cp * sy,
        cr * cp * sy - sr * sp * cy,
        cr * cp * cy + sr * sp * sy,
    )


def rpy_from_quaternion(q: Quaternion) -> tuple[float, float, float]:
    """Roll, pitch and yaw (z-y-x) of a quaternion; it need not be normalised.

    Pitch is clamped to ±π/2 at the poles (gimbal lock), where roll and yaw share one
    degree of freedom and the split between them is arbitrary.

    Raises:
        InvalidRequest: ``q`` is all zeros or not finite.
    """
    x, y, z, w = _normalised(q)
    roll = math.atan2(2.0 * (w * x + y * z), 1.0 - 2.0 * (x * x + y * y))
    pitch = math.asin(max(-1.0, min(1.0, 2.0 * (w * y - z * x))))
    yaw = math.atan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z))
    return roll, pitch, yaw


def yaw_of(q: Quaternion) -> float:
    """The heading (rotation about z) of a quaternion, in (-π, π]."""
    return rpy_from_quaternion(q)[2]


def _normalised(q: Quaternion) -> Quaternion:
    x, y, z, w = q
    norm = math.sqrt(x * x + y * y + z * z + w * w)
    if not norm > 0.0 or not math.isfinite(norm):
        raise InvalidRequest(f"the quaternion {q!r} is not a rotation (its norm is {norm})")
    return x / norm, y / norm, z / norm, w / norm
