"""Which robots the task panel shows: the Qt-free filter over a real mission's view.

A real mission with the 20-robot team feeds a :class:`MissionView` through a real mirror
(as the GUI's bridge does); the filter then picks robots by name, by the robot list and by
how each robot is, and follows the mission as it changes.
"""

from __future__ import annotations

import pytest

from rosmc_rqt_command.core.mission_view import MissionView
from rosmc_rqt_command.core.team_filter import (
    StatusFilter,
    TeamFilter,
    robot_states,
    visible_agents,
)
from rosmc_server.core import AgentStatus, SkillStatus
from tests.team_twenty import WAITING, Staged, stage, twenty_robot_library
from tests.unit.conftest import make_mission
from tests.unit.test_command_harness import Feed

S = StatusFilter


@pytest.fixture
def team() -> tuple[MissionView, Feed, Staged]:
    """The staged 20-robot mission as the GUI's view holds it."""
    library = twenty_robot_library()
    view = MissionView()
    feed = Feed(make_mission(library), view.apply)
    return view, feed, stage(feed)


def test_no_filter_shows_every_robot_in_order(team: tuple[MissionView, Feed, Staged]) -> None:
    view, _feed, staged = team
    assert visible_agents(view, staged.robots, TeamFilter()) == list(staged.robots)
    assert not TeamFilter().active


def test_names_match_any_word_case_blind(team: tuple[MissionView, Feed, Staged]) -> None:
    view, _feed, staged = team
    drones = visible_agents(view, staged.robots, TeamFilter("DRONE"))
    assert drones == [f"drone_{n}" for n in range(1, 7)]
    chosen = TeamFilter(" drone_1,  manipulator_rover_7 science_rover_2 ")
    assert visible_agents(view, staged.robots, chosen) == [
        "drone_1",
        "science_rover_2",
        "manipulator_rover_7",
    ]
    assert visible_agents(view, staged.robots, TeamFilter("no_such_robot")) == []


def test_unticked_robots_are_hidden_until_ticked_again(
    team: tuple[MissionView, Feed, Staged],
) -> None:
    view, _feed, staged = team
    chosen = TeamFilter("drone").with_shown("drone_3", False).with_shown("drone_4", False)
    assert chosen.active
    shown = visible_agents(view, staged.robots, chosen)
    assert shown == ["drone_1", "drone_2", "drone_5", "drone_6"]
    chosen = chosen.with_shown("drone_3", True)
    assert visible_agents(view, staged.robots, chosen) == [
        "drone_1",
        "drone_2",
        "drone_3",
        "drone_5",
        "drone_6",
    ]


def test_status_filters_pick_the_robots_that_need_the_operator(
    team: tuple[MissionView, Feed, Staged],
) -> None:
    view, _feed, staged = team
    shown = {s: visible_agents(view, staged.robots, TeamFilter(status=s)) for s in S}
    assert shown[S.FAILED] == list(staged.failed)
    assert shown[S.OUT_OF_CONTACT] == list(staged.out_of_contact)
    # Waiting: at a barrier, or with commands waiting for contact.
    assert shown[S.WAITING] == WAITING
    assert robot_states(view, "drone_1") == {S.ALL}
    # Name and status together: both must match.
    chosen = TeamFilter("rover", status=S.OUT_OF_CONTACT)
    assert visible_agents(view, staged.robots, chosen) == ["manipulator_rover_6"]


def test_status_filters_follow_the_mission(team: tuple[MissionView, Feed, Staged]) -> None:
    view, feed, staged = team
    failed = TeamFilter(status=S.FAILED)
    retried = next(s for s in view.view("drone_2").skills if s.status is SkillStatus.FAILURE)
    feed("retry", retried.id)  # the failure is dealt with: no longer an alarm
    assert visible_agents(view, staged.robots, failed) == []
    running = next(s for s in view.view("drone_4").skills if s.status is SkillStatus.RUNNING)
    feed("report_status", running.id, SkillStatus.FAILURE, text="lost the horizon")
    assert visible_agents(view, staged.robots, failed) == ["drone_4"]
    feed.statuses(AgentStatus("drone_5", link="up", last_heard=0.0))  # heard again
    assert visible_agents(view, staged.robots, TeamFilter(status=S.OUT_OF_CONTACT)) == [
        "manipulator_rover_6"
    ]
