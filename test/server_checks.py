#!/usr/bin/env python3
"""rostest checks of the mission server alone (test/server.test)."""

from __future__ import annotations

import threading
import unittest

from rosmc_server.venv import use_project_venv

use_project_venv()

import rospy  # noqa: E402
import rostest  # noqa: E402
from rosmc.msg import MissionEvent  # noqa: E402
from rostest_checks import wait_for  # noqa: E402

from rosmc_server import interface  # noqa: E402
from rosmc_server.core import RosmcError  # noqa: E402
from rosmc_server.ros.client import MissionClient  # noqa: E402


class MissionServerChecks(unittest.TestCase):
    """Operator services, the event stream and a refused request, against the real server."""

    def setUp(self) -> None:
        self.client = MissionClient(timeout=30.0)
        self.events: list[MissionEvent] = []
        self.lock = threading.Lock()
        self.subscriber = rospy.Subscriber(interface.EVENTS_TOPIC, MissionEvent, self.on_event)
        wait_for("the events subscription", lambda: self.subscriber.get_num_connections() > 0)

    def tearDown(self) -> None:
        self.subscriber.unregister()
        self.client.close()

    def on_event(self, event: MissionEvent) -> None:
        with self.lock:
            self.events.append(event)

    def test_library_lists_the_team(self) -> None:
        library = self.client.library()
        self.assertEqual(set(library.dynamic_agents), {"r1", "r2", "r3"})

    def test_add_then_delete_publishes_one_event_each(self) -> None:
        self.client.get_mission()
        added = self.client.add_skill("r2", "wait", {"duration": 1.5}, label="rostest")
        skill = self.client.get_mission().skill(added.skill_id)
        self.assertEqual((skill.agent, skill.params["duration"]), ("r2", 1.5))
        deleted = self.client.delete_skills([added.skill_id])
        revisions = wait_for(
            "both events",
            lambda: self._revisions_from(added.revision) or None,
        )
        self.assertEqual(revisions, [added.revision, deleted.revision])
        self.assertEqual(list(self.client.get_mission().task("r2")), [])

    def test_a_refused_request_changes_nothing(self) -> None:
        before = self.client.get_mission().revision
        with self.assertRaises(RosmcError) as refused:
            self.client.add_skill("r1", "wait", {"duration": -4.0})
        self.assertIn("duration", str(refused.exception))
        self.assertEqual(self.client.get_mission().revision, before)

    def _revisions_from(self, first: int) -> list[int]:
        with self.lock:
            found = [event.revision for event in self.events if event.revision >= first]
        return found if len(found) >= 2 else []


if __name__ == "__main__":
    rospy.init_node("server_checks", anonymous=True)
    rostest.rosrun("rosmc", "server_checks", MissionServerChecks)
