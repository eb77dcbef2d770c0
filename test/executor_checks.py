#!/usr/bin/env python3
"""rostest checks of a mission executor with the server (test/executor.test)."""

from __future__ import annotations

import unittest

from rosmc_server.venv import use_project_venv

use_project_venv()

import rospy  # noqa: E402
import rostest  # noqa: E402
from rosmc.msg import AgentStates, LinkState  # noqa: E402
from rostest_checks import statuses, wait_for  # noqa: E402

from rosmc_server import interface  # noqa: E402
from rosmc_server.ros.client import MissionClient  # noqa: E402
from rosmc_server.ros.client.results import ControlCommand  # noqa: E402

ROBOT = "r1"


class ExecutorChecks(unittest.TestCase):
    """The robot link comes up, and synchronized skills run to their outcomes on the robot."""

    def setUp(self) -> None:
        self.client = MissionClient(timeout=30.0)

    def tearDown(self) -> None:
        self.client.close()

    def test_link_up_then_synchronized_skills_run(self) -> None:
        wait_for("r1's link to come up", self.link_up)
        self.client.get_mission()
        self.client.add_skill(ROBOT, "wait", {"duration": 0.3})
        self.client.add_skill(ROBOT, "count", {"steps": 3, "period": 0.1})
        self.client.add_skill(ROBOT, "probe", {"duration": 0.1, "fail": True})
        synced = self.client.synchronize(ROBOT)
        self.assertEqual(len(synced.skill_ids), 3)
        wait_for(
            "the upload to be confirmed",
            lambda: statuses(self.client, ROBOT) == ["IDLE_SYNCHRONIZED"] * 3,
        )
        self.client.control(ControlCommand.START, ROBOT)
        final = ["SUCCESS", "SUCCESS", "FAILURE"]
        wait_for("the skills to finish", lambda: statuses(self.client, ROBOT) == final)
        failed = self.client.get_mission().task(ROBOT)[2]
        self.assertIn("failed", failed.status_text)

    def link_up(self) -> bool:
        states = rospy.wait_for_message(interface.AGENT_STATES_TOPIC, AgentStates, timeout=10.0)
        return any(
            state.agent == ROBOT and state.link.state == LinkState.UP for state in states.agents
        )


if __name__ == "__main__":
    rospy.init_node("executor_checks", anonymous=True)
    rostest.rosrun("rosmc", "executor_checks", ExecutorChecks)
