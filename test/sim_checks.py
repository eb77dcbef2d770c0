#!/usr/bin/env python3
"""rostest checks of the simulated team with the server (test/sim.test)."""

from __future__ import annotations

import unittest

from rosmc_server.venv import use_project_venv

use_project_venv()

import rospy  # noqa: E402
import rostest  # noqa: E402
import tf2_ros  # noqa: E402
from rosgraph_msgs.msg import Clock  # noqa: E402
from rosmc.msg import AgentStates, LinkState, ScienceState  # noqa: E402
from rostest_checks import wait_for  # noqa: E402

from rosmc_server import interface  # noqa: E402
from rosmc_sim.ros.topics import SCIENCE_TOPIC  # noqa: E402

ROBOTS = ("drone", "science_rover", "manipulator_rover")


class SimulatedTeamChecks(unittest.TestCase):
    """The sim publishes its clock, TF and science; every robot's link to the server comes up."""

    def test_sim_time_advances(self) -> None:
        first = rospy.wait_for_message("/clock", Clock, timeout=30.0).clock
        later = wait_for(
            "/clock to advance",
            lambda: (t := rospy.wait_for_message("/clock", Clock, timeout=5.0).clock) > first and t,
        )
        self.assertGreater(later, first)

    def test_every_robot_is_in_tf(self) -> None:
        buffer = tf2_ros.Buffer()
        listener = tf2_ros.TransformListener(buffer)
        for robot in ROBOTS:
            frame = interface.base_link(robot)
            wait_for(
                f"TF {interface.MAP_FRAME} -> {frame}",
                lambda frame=frame: buffer.can_transform(interface.MAP_FRAME, frame, rospy.Time()),
            )
        del listener

    def test_science_state_is_latched(self) -> None:
        science = rospy.wait_for_message(SCIENCE_TOPIC, ScienceState, timeout=30.0)
        self.assertGreaterEqual(science.score, 0.0)

    def test_every_robot_links_to_the_server(self) -> None:
        def all_up() -> bool:
            states = rospy.wait_for_message(interface.AGENT_STATES_TOPIC, AgentStates, timeout=10.0)
            up = {s.agent for s in states.agents if s.link.state == LinkState.UP}
            return set(ROBOTS) <= up

        wait_for("every robot's link to come up", all_up)


if __name__ == "__main__":
    rospy.init_node("sim_checks", anonymous=True)
    rostest.rosrun("rosmc", "sim_checks", SimulatedTeamChecks)
