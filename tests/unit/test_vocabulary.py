"""One vocabulary: the command GUI, rviz and ``rosmc`` say a status, a number and a colour alike.

Each view is driven through its own public functions (the command GUI's presentation, the
rviz status block, the text of ``rosmc``), and what it shows is checked against
:mod:`rosmc_server.core.views.vocabulary`; and the simulator and rviz paint bodies from one palette.
"""

from __future__ import annotations

from typing import Any

import pytest

from rosmc_rqt_command.core import presentation
from rosmc_rviz_markers.core import icons
from rosmc_server.core import EventKind, Mission, SkillInstance, SkillStatus
from rosmc_server.core.robots.agent_status import AgentStatus
from rosmc_server.core.views import geometry
from rosmc_server.core.views.vocabulary import (
    OPERATOR_EVENTS,
    PALETTE,
    ROBOT_EVENTS,
    STATUS_COLOURS,
    STATUS_MARKS,
    STATUS_WORDS,
    counted,
    number,
    rgb,
)
from rosmc_server.text import format_agent_status, format_tasks
from rosmc_sim.core import world


@pytest.mark.parametrize("status", list(SkillStatus))
def test_the_command_gui_says_and_paints_each_status_from_the_vocabulary(
    status: SkillStatus,
) -> None:
    skill = SkillInstance("s-1", "drone", "survey", "survey A", {}, status=status)
    assert presentation.status_text(skill) == STATUS_WORDS[status]
    if status is not SkillStatus.FAILURE:  # an unresolved failure is the alarm red
        assert presentation.row_colour(skill) == STATUS_COLOURS[status]


@pytest.mark.parametrize("status", [s for s in SkillStatus if s is not SkillStatus.IDLE])
def test_rviz_says_and_paints_each_status_from_the_vocabulary(status: SkillStatus) -> None:
    row = icons.skill_row("survey A", status)
    assert row.text.startswith(f"survey A {STATUS_MARKS[status]} ")
    assert row.text.lower().endswith(STATUS_WORDS[status])
    assert (row.color.r, row.color.g, row.color.b) == rgb(STATUS_COLOURS[status])


def test_rosmc_marks_a_running_skill_with_the_vocabulary(mission: Mission, drv: Any) -> None:
    first = drv.add("alpha", "move", label="go")
    drv.sync("alpha")
    drv.run(first)
    line = next(x for x in format_tasks(mission.state).splitlines() if first in x)
    assert line.strip().startswith(STATUS_MARKS[SkillStatus.RUNNING])


def test_every_status_has_a_distinct_word_mark_and_colour() -> None:
    for table in (STATUS_WORDS, STATUS_MARKS, STATUS_COLOURS):
        assert set(table) == set(SkillStatus)
        assert len(set(table.values())) == len(SkillStatus)


def test_battery_and_wifi_read_the_same_in_the_gui_and_in_rosmc() -> None:
    status = AgentStatus("drone", link="up", battery=0.973, wifi_signal=-54.4, in_coverage=True)
    gui, text = presentation.link_summary(status), format_agent_status(status)
    for words in ("battery 97%", "Wi-Fi good"):
        assert words in gui and words in text
    assert "Wi-Fi good (-54 dBm)" in text  # the number too, for whoever reads a terminal
    health = icons.status_rows(status)[1].text
    assert "97%" in health and "-54 dBm" in health


@pytest.mark.parametrize(
    ("value", "decimals", "text"),
    [
        (2.0, 2, "2"),
        (1.5, 2, "1.5"),
        (1.23456, 2, "1.23"),
        (1.23456, 3, "1.235"),
        (-0.0004, 3, "0"),
        (float("inf"), 2, "inf"),
    ],
)
def test_numbers_for_people(value: float, decimals: int, text: str) -> None:
    assert number(value, decimals) == text


def test_robot_and_operator_events_split_every_kind() -> None:
    assert frozenset(EventKind) == ROBOT_EVENTS | OPERATOR_EVENTS
    assert not ROBOT_EVENTS & OPERATOR_EVENTS
    assert EventKind.STATUS_CHANGED in ROBOT_EVENTS and EventKind.SKILL_ADDED in OPERATOR_EVENTS


def test_rviz_paints_bodies_with_the_simulators_palette() -> None:
    assert world.PALETTE is PALETTE  # what pybullet paints with
    assert set(geometry.BODY_COLORS) == set(geometry.BodyKind)
    for kind in ("drone", "science_rover", "manipulator_rover", "lander"):
        body = geometry.BODY_COLORS[geometry.body_kind(kind)]
        assert (body.r, body.g, body.b, body.a) == PALETTE[kind]


@pytest.mark.parametrize(
    ("count", "noun", "plural", "text"),
    [
        (1, "skill", "", "1 skill"),
        (0, "stone", "", "0 stones"),
        (2, "planned skill", "", "2 planned skills"),
        (3, "damaged byte range", "", "3 damaged byte ranges"),
        (2, "barrier release", "", "2 barrier releases"),
        (2, "batch", "batches", "2 batches"),
    ],
)
def test_counts_take_the_plural_unless_one(count: int, noun: str, plural: str, text: str) -> None:
    assert counted(count, noun, plural) == text
