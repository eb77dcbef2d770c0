"""The simulated robot's own pose, for its mission executor (``~pose_source``).

A real robot gives its executor a pose source of its own (localisation in the map
frame); the simulated one reads its odometry, ``/<robot>/odom`` (nav_msgs/Odometry,
frame ``map``), which the simulator publishes from the robot's sim pose.
"""

from __future__ import annotations

import threading

import rospy
from nav_msgs.msg import Odometry

from rosmc_server.core import Pose
from rosmc_server.core.world.frames import yaw_of
from rosmc_server.executor.core.lost_link import PoseSource

from .topics import odom_topic


class OdometryPose:
    """The latest pose heard on a robot's odometry (None until the first message)."""

    def __init__(self, robot: str) -> None:
        self._lock = threading.Lock()
        self._pose: Pose | None = None
        self._subscriber = rospy.Subscriber(
            odom_topic(robot), Odometry, self._on_odom, queue_size=1
        )

    def _on_odom(self, msg: Odometry) -> None:
        p, q = msg.pose.pose.position, msg.pose.pose.orientation
        pose = Pose(p.x, p.y, p.z, 0.0, 0.0, yaw_of((q.x, q.y, q.z, q.w)))
        with self._lock:
            self._pose = pose

    def __call__(self) -> Pose | None:
        with self._lock:
            return self._pose


def pose_source(agent: str) -> PoseSource:
    """The executor's pose source of the simulated robot ``agent``."""
    return OdometryPose(agent)
