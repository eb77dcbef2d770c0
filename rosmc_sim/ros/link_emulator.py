"""Emulated ground-robot radio links: ``/rosmc/link_emulator``.

For every agent it relays the robot-link topics between the ground names
(``/rosmc/link/<agent>/...``) and the robot names (``/<agent>/link/...``), which
the executors use when started with ``robot_side:=true``:

* ground -> robot: ``command`` (rosmc/RobotCommand), ``report_ack`` (rosmc/ReportAck);
* robot -> ground: ``ack`` (rosmc/RobotAck), ``report`` (rosmc/RobotReport),
  ``snapshot`` (rosmc/ExecutorSnapshot).

Each direction is a :class:`DelayLine` with the one-way latency (ROS time, so
sim time scales it), drop probability and blackout state of that agent.

Subscribes ``/<agent>/link/blackout`` (std_msgs/Bool): true cuts the link (the
simulator's coverage model, or a test, publishes it).

Parameters (private): ``~agents`` (list of str), or ``~scenario`` (str, its robots; relative
to ``~cwd``), ``~cwd`` (str, where roslaunch was typed), ``~latency`` (float, s, 0),
``~drop`` (float, 0..1, 0), ``~seed`` (int, for reproducible loss), ``~rate`` (Hz, 200).
"""

from __future__ import annotations

import argparse
import logging
import os
import random
import sys
import threading
import time
from collections.abc import Sequence
from pathlib import Path

import rosmc.msg as wire
import rospy
from std_msgs.msg import Bool

from rosmc_server.common.ros.graph_join import join_graph
from rosmc_server.common.ros.logging_bridge import bridge_logging_to_rosout
from rosmc_server.interface import ground_link, robot_link

from ..core.delay_line import DelayLine
from ..core.scenario import load_scenario

_log = logging.getLogger(__name__)

Line = DelayLine[tuple[rospy.Publisher, object]]

# (topic field, message type, goes from ground to robot)
_TOPICS = (
    ("command", wire.RobotCommand, True),
    ("report_ack", wire.ReportAck, True),
    ("ack", wire.RobotAck, False),
    ("report", wire.RobotReport, False),
    ("snapshot", wire.ExecutorSnapshot, False),
)


class AgentRadio:
    """Both directions of one agent's link."""

    def __init__(self, agent: str, latency: float, drop: float, rng: random.Random) -> None:
        self.agent = agent
        self.uplink: DelayLine[tuple[rospy.Publisher, object]] = DelayLine(latency, drop, rng=rng)
        self.downlink: DelayLine[tuple[rospy.Publisher, object]] = DelayLine(latency, drop, rng=rng)
        ground, robot = ground_link(agent), robot_link(agent)
        self._subscribers = []
        for name, msg_type, to_robot in _TOPICS:
            source = getattr(ground if to_robot else robot, name)
            target = getattr(robot if to_robot else ground, name)
            publisher = rospy.Publisher(target, msg_type, queue_size=1000)
            line = self.uplink if to_robot else self.downlink
            self._subscribers.append(
                rospy.Subscriber(
                    source, msg_type, self._relay, callback_args=(line, publisher), queue_size=1000
                )
            )
        self._subscribers.append(
            rospy.Subscriber(f"/{agent}/link/blackout", Bool, self._on_blackout, queue_size=10)
        )
        self.lock = threading.Lock()

    def _relay(
        self, msg: object, args: tuple[DelayLine[tuple[rospy.Publisher, object]], rospy.Publisher]
    ) -> None:
        line, publisher = args
        with self.lock:
            line.push((publisher, msg), rospy.get_time())

    def _on_blackout(self, msg: Bool) -> None:
        with self.lock:
            if msg.data != self.uplink.blackout:
                _log.info("link %s: %s", self.agent, "blackout" if msg.data else "restored")
            self.uplink.set_blackout(msg.data)
            self.downlink.set_blackout(msg.data)

    def deliver(self, now: float) -> None:
        """Publish whatever is due in both directions."""
        with self.lock:
            due = self.uplink.due(now) + self.downlink.due(now)
        for publisher, msg in due:
            publisher.publish(msg)


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of ``link_emulator``."""
    args = rospy.myargv(list(argv) if argv is not None else sys.argv)
    argparse.ArgumentParser(
        prog="link_emulator",
        description="Relays the robot links with latency, loss and blackouts "
        "(_agents:=[a,b] _latency:=SECONDS _drop:=P).",
    ).parse_args(args[1:])
    join_graph("link_emulator")
    bridge_logging_to_rosout()
    agents = rospy.get_param("~agents", [])
    if isinstance(agents, str):
        agents = [a for a in agents.replace(",", " ").split() if a]
    scenario = str(rospy.get_param("~scenario", ""))
    if not agents and scenario:
        cwd = str(rospy.get_param("~cwd", "") or os.getcwd())
        agents = [robot.name for robot in load_scenario(Path(cwd, scenario)).robots]
    if not agents:
        _log.critical("link emulator: set ~agents (or ~scenario) to the robots to relay")
        return 2
    rng = random.Random(int(rospy.get_param("~seed", 0)))
    latency = float(rospy.get_param("~latency", 0.0))
    drop = float(rospy.get_param("~drop", 0.0))
    radios = [AgentRadio(agent, latency, drop, rng) for agent in agents]
    _log.info("link emulator: %s, latency %.3g s, drop %.2g", ", ".join(agents), latency, drop)
    period = 1.0 / float(rospy.get_param("~rate", 200.0))
    while not rospy.is_shutdown():
        now = rospy.get_time()
        for radio in radios:
            radio.deliver(now)
        time.sleep(period)
    return 0
