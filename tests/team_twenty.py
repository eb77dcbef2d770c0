"""The 20-robot team of ``rosmc_sim/scenarios/twenty_robots.yaml`` as a mission the command GUI
shows.

:func:`twenty_robot_library` gives the shipped Mars library with the scenario's 20 robots
as its agents (each robot kind on its model). :func:`stage` fills a mission through the
unit harness's :class:`~tests.unit.test_command_harness.Feed`: every robot has work on
board and planned, and a few robots need the operator (a failure, a barrier wait, no
contact). Used by the large-team GUI tests and ``tools/command_gui_team_screenshot.py``.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

import yaml

from rosmc_server.core import AgentStatus, Library, SkillStatus
from rosmc_server.core.skills.library import library_from_dict
from rosmc_sim.core.scenario import load_scenario

REPO = Path(__file__).resolve().parents[1]
SCENARIO = REPO / "rosmc_sim" / "scenarios" / "twenty_robots.yaml"
TWENTY_LIBRARY = REPO / "rosmc_server" / "config" / "mars_twenty_robots.yaml"
MODELS = {"drone": "drone_scout", "science_rover": "rover_science"}
MODELS["manipulator_rover"] = "rover_manipulator"
FIRST_SKILL = {"drone": "take_off", "science_rover": "explore"}
FIRST_SKILL["manipulator_rover"] = "pick_box"
# The robots :func:`stage` leaves waiting (at a barrier, or with commands for a cut-off robot).
WAITING = ["drone_5", "science_rover_3", "manipulator_rover_3", "manipulator_rover_6"]


@dataclass(frozen=True)
class Staged:
    """Which robots of the staged mission need the operator, and why."""

    robots: tuple[str, ...]
    failed: tuple[str, ...]
    waiting: tuple[str, ...]
    out_of_contact: tuple[str, ...]


def twenty_robot_library() -> Library:
    """The Mars library with the 20-robot scenario's robots (and the lander)."""
    return library_from_dict(twenty_robot_library_data(), "mars_twenty_robots.yaml")


def twenty_robot_library_data() -> dict[str, Any]:
    """:func:`twenty_robot_library` as library file data (for a server to load): the shipped
    ``mars_twenty_robots.yaml`` (``tools/team_library.py`` makes it)."""
    data: dict[str, Any] = yaml.safe_load(TWENTY_LIBRARY.read_text())
    return data


def stage(feed: Any) -> Staged:
    """Give every robot work; fail one drone, let two rovers wait, cut two robots off."""
    kinds = {robot.name: robot.kind for robot in load_scenario(SCENARIO).robots}
    robots = tuple(kinds)
    first: dict[str, str] = {}
    for robot, kind in kinds.items():
        first[robot] = feed.add(robot, FIRST_SKILL[kind])
        feed.add(robot, "navigate_to")
        feed.add(robot, "return_to_lander")
        feed.sync(robot, first[robot])
        feed("report_status", first[robot], SkillStatus.RUNNING)
    failed = ("drone_2",)
    feed("report_status", first["drone_2"], SkillStatus.FAILURE, text="rotor fault")
    waiting = ("science_rover_3", "manipulator_rover_3")
    identify = [feed.add(robot, "identify_stones") for robot in waiting]
    feed("add_barrier", identify)
    for robot, skill in zip(waiting, identify, strict=True):
        feed("report_status", first[robot], SkillStatus.SUCCESS)
        for step in feed.sync(robot):
            if step != skill:
                feed("report_status", step, SkillStatus.RUNNING)
                feed("report_status", step, SkillStatus.SUCCESS)
        feed("report_status", skill, SkillStatus.SYNCWAITING)
    out_of_contact = ("drone_5", "manipulator_rover_6")
    feed.statuses(
        *(AgentStatus(r, link="up", last_heard=0.0, battery=0.8) for r in robots),
        *(AgentStatus(r, link="down", last_heard=95.0, commands_waiting=1) for r in out_of_contact),
    )
    return Staged(robots, failed, waiting, out_of_contact)
