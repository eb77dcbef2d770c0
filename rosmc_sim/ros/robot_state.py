"""Where the agents are and how they fare, on ROS: TF, odometry, telemetry, link blackouts.

Publishes (wall rates, so a fast simulation does not flood the graph):

* ``/tf`` (tf2_msgs/TFMessage, through tf2_ros.TransformBroadcaster): ``map`` ->
  ``<agent>/base_link`` for every robot, the lander (at the origin) and every
  payload box (following its carrier), at :data:`TF_PERIOD`;
* ``/<robot>/odom`` (nav_msgs/Odometry): frame ``map``, child ``<robot>/base_link``,
  twist in the child frame, at :data:`TF_PERIOD`;
* ``/<robot>/telemetry`` (rosmc/Telemetry): pose, battery, Wi-Fi signal and
  coverage, at :data:`TELEMETRY_PERIOD`;
* ``/<robot>/link/blackout`` (std_msgs/Bool, latched): not in coverage, on every
  change and every :data:`BLACKOUT_PERIOD`. Coverage is evaluated every
  :data:`COVERAGE_PERIOD` seconds of sim time.

All stamps are sim time.
"""

from __future__ import annotations

import logging
import math

import rosmc.msg as wire
import rospy
import tf2_ros
from geometry_msgs.msg import Quaternion, TransformStamped, Vector3
from nav_msgs.msg import Odometry
from std_msgs.msg import Bool

from rosmc_server.core.world.frames import quaternion_from_rpy
from rosmc_server.interface import MAP_FRAME, TELEMETRY_TOPIC, base_link

from ..core.sim import Robot, Simulation
from ..core.world import BOX_SIZE
from .timing import Throttle
from .topics import blackout_topic, odom_topic

TF_PERIOD = 0.05
TELEMETRY_PERIOD = 0.5
BLACKOUT_PERIOD = 1.0
COVERAGE_PERIOD = 0.25
LANDER = "lander"

_log = logging.getLogger(__name__)
Pose4 = tuple[float, float, float, float]  # x, y, z, yaw


def yaw_quaternion(yaw: float) -> Quaternion:
    """A rotation about z as a ``geometry_msgs/Quaternion``."""
    return Quaternion(*quaternion_from_rpy(yaw=yaw))


class RobotStatePublisher:
    """Publishes the agents' poses and the robots' odometry, telemetry and link state."""

    def __init__(self, sim: Simulation) -> None:
        self.sim = sim
        self._robots = list(sim.robots.values())
        self._tf = tf2_ros.TransformBroadcaster()
        self._odom = {
            r.name: rospy.Publisher(odom_topic(r.name), Odometry, queue_size=5)
            for r in self._robots
        }
        self._telemetry = {
            r.name: rospy.Publisher(
                TELEMETRY_TOPIC.format(agent=r.name), wire.Telemetry, queue_size=5
            )
            for r in self._robots
        }
        self._blackout = {
            r.name: rospy.Publisher(blackout_topic(r.name), Bool, queue_size=5, latch=True)
            for r in self._robots
        }
        self._pose: dict[str, Pose4] = {r.name: _pose_of(r) for r in self._robots}
        self._pose_time = 0.0  # the sim time of ``_pose``
        self._velocity: dict[str, Pose4] = {r.name: (0.0, 0.0, 0.0, 0.0) for r in self._robots}
        self._wifi: dict[str, tuple[float, bool]] = {}
        self._coverage_time = float("-inf")
        self._tf_throttle = Throttle(TF_PERIOD)
        self._telemetry_throttle = Throttle(TELEMETRY_PERIOD)
        self._blackout_throttle = Throttle(BLACKOUT_PERIOD)

    def coverage(self, robot: str) -> tuple[float, bool]:
        """The latest Wi-Fi signal (dBm) and coverage of a robot."""
        return self._wifi.get(robot, (math.nan, False))

    def after_step(self, now: float) -> None:
        """Re-check coverage when due, and publish what is due at wall time ``now``."""
        if self.sim.time - self._coverage_time >= COVERAGE_PERIOD - 1e-9:
            self._update_coverage()
        if self._tf_throttle.due(now):
            self._track()
            stamp = rospy.Time.from_sec(self.sim.time)
            self._publish_tf(stamp)
            for robot in self._robots:
                self._odom[robot.name].publish(self._odometry(robot, stamp))
        if self._telemetry_throttle.due(now):
            stamp = rospy.Time.from_sec(self.sim.time)
            for robot in self._robots:
                self._telemetry[robot.name].publish(self._telemetry_msg(robot, stamp))
        if self._blackout_throttle.due(now):
            for robot in self._robots:
                self._blackout[robot.name].publish(Bool(not self.coverage(robot.name)[1]))

    def _track(self) -> None:
        """The velocities since the last odometry: its twist is their mean over that time.

        Sampled only when odometry goes out, not every step: run fast, the sim steps
        many times per message, and per-step tracking cost a twentieth of a step.
        """
        dt = self.sim.time - self._pose_time
        if dt <= 0:
            return
        self._pose_time = self.sim.time
        for robot in self._robots:
            x0, y0, z0, yaw0 = self._pose[robot.name]
            pose = _pose_of(robot)
            turn = (pose[3] - yaw0 + math.pi) % (2 * math.pi) - math.pi
            self._velocity[robot.name] = (
                (pose[0] - x0) / dt,
                (pose[1] - y0) / dt,
                (pose[2] - z0) / dt,
                turn / dt,
            )
            self._pose[robot.name] = pose

    def _update_coverage(self) -> None:
        self._coverage_time = self.sim.time
        for robot in self._robots:
            signal, covered = self.sim.wifi(robot)
            previous = self._wifi.get(robot.name)
            self._wifi[robot.name] = (signal, covered)
            if previous is None or previous[1] != covered:
                if previous is not None:
                    _log.info("%s %s coverage", robot.name, "entered" if covered else "left")
                self._blackout[robot.name].publish(Bool(not covered))

    def _publish_tf(self, stamp: rospy.Time) -> None:
        transforms = [self._transform(r.name, stamp, r.x, r.y, r.z, r.yaw) for r in self._robots]
        transforms.append(self._transform(LANDER, stamp, 0.0, 0.0, 0.0, 0.0))
        for box in self.sim.boxes.values():
            z = box.z - BOX_SIZE / 2  # the box's bottom
            carrier = self.sim.robots.get(box.carried_by)
            yaw = carrier.yaw if carrier is not None else 0.0
            transforms.append(self._transform(box.spec.name, stamp, box.x, box.y, z, yaw))
        self._tf.sendTransform(transforms)

    @staticmethod
    def _transform(
        agent: str, stamp: rospy.Time, x: float, y: float, z: float, yaw: float
    ) -> TransformStamped:
        msg = TransformStamped()
        msg.header.stamp = stamp
        msg.header.frame_id = MAP_FRAME
        msg.child_frame_id = base_link(agent)
        msg.transform.translation = Vector3(x, y, z)
        msg.transform.rotation = yaw_quaternion(yaw)
        return msg

    def _odometry(self, robot: Robot, stamp: rospy.Time) -> Odometry:
        msg = Odometry()
        msg.header.stamp = stamp
        msg.header.frame_id = MAP_FRAME
        msg.child_frame_id = base_link(robot.name)
        msg.pose.pose.position.x, msg.pose.pose.position.y = robot.x, robot.y
        msg.pose.pose.position.z = robot.z
        msg.pose.pose.orientation = yaw_quaternion(robot.yaw)
        vx, vy, vz, wz = self._velocity[robot.name]
        cos, sin = math.cos(robot.yaw), math.sin(robot.yaw)
        msg.twist.twist.linear = Vector3(vx * cos + vy * sin, -vx * sin + vy * cos, vz)
        msg.twist.twist.angular.z = wz
        return msg

    def _telemetry_msg(self, robot: Robot, stamp: rospy.Time) -> wire.Telemetry:
        signal, covered = self.coverage(robot.name)
        return wire.Telemetry(
            agent=robot.name,
            stamp=stamp,
            frame_id=MAP_FRAME,
            pose=wire.Pose6D(robot.x, robot.y, robot.z, 0.0, 0.0, robot.yaw),
            battery=robot.battery,
            wifi_signal=signal,
            in_coverage=covered,
        )


def _pose_of(robot: Robot) -> Pose4:
    return (robot.x, robot.y, robot.z, robot.yaw)
