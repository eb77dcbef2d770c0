#!/usr/bin/env python3
"""rostest checks of the rviz marker node with the server (test/markers.test)."""

from __future__ import annotations

import threading
import unittest

from rosmc_server.venv import use_project_venv

use_project_venv()

import rospy  # noqa: E402
import rostest  # noqa: E402
from rostest_checks import wait_for  # noqa: E402
from visualization_msgs.msg import InteractiveMarkerInit, InteractiveMarkerUpdate  # noqa: E402

from rosmc_rviz_markers.core.specs import robot_name, task_name  # noqa: E402
from rosmc_rviz_markers.topics import MARKERS_NS  # noqa: E402
from rosmc_server.core import Pose, TaskMarker  # noqa: E402
from rosmc_server.core.skills.params import MarkerType  # noqa: E402
from rosmc_server.ros.client import MissionClient  # noqa: E402

ROBOTS = ("drone", "science_rover", "manipulator_rover")


class MarkerNodeChecks(unittest.TestCase):
    """Every robot has an interactive marker; a task marker added on the server appears."""

    def setUp(self) -> None:
        self.names: set[str] = set()
        self.lock = threading.Lock()
        self.updates = rospy.Subscriber(
            f"{MARKERS_NS}/update", InteractiveMarkerUpdate, self.on_update
        )

    def tearDown(self) -> None:
        self.updates.unregister()

    def on_update(self, update: InteractiveMarkerUpdate) -> None:
        with self.lock:
            self.names.update(marker.name for marker in update.markers)

    def test_every_robot_has_a_marker(self) -> None:
        def robots_shown() -> bool:
            init = rospy.wait_for_message(
                f"{MARKERS_NS}/update_full", InteractiveMarkerInit, timeout=10.0
            )
            shown = {marker.name for marker in init.markers}
            return {robot_name(robot) for robot in ROBOTS} <= shown

        wait_for("a marker for every robot", robots_shown)

    def test_a_task_marker_added_on_the_server_appears(self) -> None:
        wait_for("the update subscription", lambda: self.updates.get_num_connections() > 0)
        with self.lock:  # before the add: its update may arrive before add_marker returns
            self.names.clear()
        with MissionClient(timeout=30.0) as client:
            client.get_mission()
            added = client.add_task_marker(
                TaskMarker("rostest_flag", MarkerType.POSITION, Pose(3.0, -2.0, 0.0))
            )
        wait_for("the new task marker", lambda: self._seen(task_name(added.name)))

    def _seen(self, name: str) -> bool:
        with self.lock:
            return name in self.names


if __name__ == "__main__":
    rospy.init_node("markers_checks", anonymous=True)
    rostest.rosrun("rosmc", "markers_checks", MarkerNodeChecks)
