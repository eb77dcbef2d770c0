"""How rows look: a colour and words per status, pending transfers, barriers, failures.

The rows are those of the real widget after real mission changes; the palette itself
is checked for what an operator relies on (no two statuses alike, failure stands out,
text readable on every background).
"""

from __future__ import annotations

import itertools
from collections.abc import Iterator
from dataclasses import replace

import pytest
from python_qt_binding.QtCore import Qt

from rosmc_rqt_command.core import presentation as p
from rosmc_rqt_command.qt.task_model import STATUS, TAG
from rosmc_server.core import AgentStatus, Library, Mission, SkillStatus
from tests.unit.test_command_harness import Gui, open_gui

S = SkillStatus


@pytest.fixture
def gui(mission: Mission, library: Library) -> Iterator[Gui]:
    """A command widget following the ``mission`` fixture."""
    yield from open_gui(mission, library)


def rgb(colour: str) -> tuple[int, int, int]:
    return int(colour[1:3], 16), int(colour[3:5], 16), int(colour[5:7], 16)


def luminance(colour: str) -> float:
    def channel(value: int) -> float:
        c = value / 255
        return c / 12.92 if c <= 0.03928 else ((c + 0.055) / 1.055) ** 2.4

    r, g, b = (channel(v) for v in rgb(colour))
    return 0.2126 * r + 0.7152 * g + 0.0722 * b


def contrast(a: str, b: str) -> float:
    high, low = sorted((luminance(a), luminance(b)), reverse=True)
    return (high + 0.05) / (low + 0.05)


def test_every_status_has_its_own_colour() -> None:
    colours = {**{s.name: c for s, c in p.STATUS_COLOURS.items()}}
    colours["transfer"] = p.TRANSFER_COLOUR
    colours["settled failure"] = p.SETTLED_FAILURE_COLOUR
    for (a, ca), (b, cb) in itertools.combinations(colours.items(), 2):
        distance = sum((x - y) ** 2 for x, y in zip(rgb(ca), rgb(cb), strict=True)) ** 0.5
        assert distance > 40, f"{a} {ca} and {b} {cb} look alike"
    # "done" and "on robot" in particular: one is history, the other still to come.
    done, on_robot = p.STATUS_COLOURS[S.SUCCESS], p.STATUS_COLOURS[S.IDLE_SYNCHRONIZED]
    assert sum(abs(x - y) for x, y in zip(rgb(done), rgb(on_robot), strict=True)) > 60


def test_failure_stands_out() -> None:
    failure = p.STATUS_COLOURS[S.FAILURE]
    red, green, blue = rgb(failure)
    assert red > 180 and green < 100 and blue < 100  # a strong red
    others = [c for s, c in p.STATUS_COLOURS.items() if s is not S.FAILURE]
    assert all(luminance(failure) < luminance(c) for c in others)  # the darkest row


def test_text_is_readable_on_every_row(gui: Gui) -> None:
    feed = gui.feed
    for status in (S.IDLE, S.IDLE_SYNCHRONIZED, S.SYNCWAITING, S.RUNNING, S.PAUSED):
        background = p.STATUS_COLOURS[status]
        assert contrast(background, p.TEXT_COLOUR) >= 7, status
    assert contrast(p.STATUS_COLOURS[S.FAILURE], p.ALARM_TEXT_COLOUR) >= 4.5
    assert contrast(p.STATUS_COLOURS[S.SUCCESS], p.DONE_TEXT_COLOUR) >= 4.5
    assert contrast(p.TRANSFER_COLOUR, p.TEXT_COLOUR) >= 7
    assert contrast(p.SETTLED_FAILURE_COLOUR, p.DONE_TEXT_COLOUR) >= 4.5
    skill = feed.add("alpha")
    feed.sync("alpha")
    feed("report_status", skill, S.RUNNING)
    feed("report_status", skill, S.FAILURE)
    foreground = gui.cell("alpha", False, 0, STATUS, Qt.ForegroundRole).color().name()
    assert foreground == p.ALARM_TEXT_COLOUR
    assert gui.cell("alpha", False, 0, STATUS, Qt.FontRole).bold()


def test_rows_take_the_colour_and_words_of_their_status(gui: Gui) -> None:
    feed = gui.feed
    planned = feed.add("alpha", "wait", label="rest")
    assert gui.colour("alpha", True, 0) == p.STATUS_COLOURS[S.IDLE]
    assert gui.cell("alpha", True, 0, STATUS, Qt.DisplayRole) == "planned"

    feed.sync("alpha", confirm=False)
    assert gui.colour("alpha", True, 0) == p.TRANSFER_COLOUR
    assert gui.cell("alpha", True, 0, STATUS, Qt.DisplayRole) == "uploading…"
    assert gui.cell("alpha", True, 0, STATUS, Qt.FontRole).italic()
    feed("confirm_synchronized", "alpha", [planned])
    assert gui.colour("alpha", False, 0) == p.STATUS_COLOURS[S.IDLE_SYNCHRONIZED]
    assert gui.cell("alpha", False, 0, STATUS, Qt.DisplayRole) == "on robot"

    feed("unsynchronize", "alpha", planned)
    assert gui.colour("alpha", False, 0) == p.TRANSFER_COLOUR
    assert gui.cell("alpha", False, 0, STATUS, Qt.DisplayRole) == "removing…"
    feed("confirm_unsynchronized", "alpha", [planned])
    assert gui.ids("alpha", True) == [planned]
    assert gui.colour("alpha", True, 0) == p.STATUS_COLOURS[S.IDLE]

    feed.sync("alpha")
    for status, words in (
        (S.RUNNING, "running"),
        (S.PAUSED, "paused"),
        (S.RUNNING, "running"),
        (S.SUCCESS, "done"),
    ):
        feed("report_status", planned, status)
        assert gui.colour("alpha", False, 0) == p.STATUS_COLOURS[status], status
        assert gui.cell("alpha", False, 0, STATUS, Qt.DisplayRole) == words
    assert gui.cell("alpha", False, 0, STATUS, Qt.ForegroundRole).color().name() == (
        p.DONE_TEXT_COLOUR
    )


def test_failures_say_why_and_fade_once_settled(gui: Gui) -> None:
    feed = gui.feed
    skill = feed.add("alpha", "wait")
    feed.sync("alpha")
    feed("report_status", skill, S.RUNNING)
    feed("report_status", skill, S.FAILURE, text="wheel stuck in sand")
    assert gui.colour("alpha", False, 0) == p.STATUS_COLOURS[S.FAILURE]
    assert gui.cell("alpha", False, 0, STATUS, Qt.DisplayRole) == "failed"
    assert "wheel stuck in sand" in gui.cell("alpha", False, 0, STATUS, Qt.ToolTipRole)
    feed("retry", skill)
    assert gui.colour("alpha", False, 0) == p.SETTLED_FAILURE_COLOUR
    assert gui.cell("alpha", False, 0, STATUS, Qt.DisplayRole) == "failed (retried)"
    assert gui.cell("alpha", False, 1, STATUS, Qt.DisplayRole) == "on robot, try 2"


def test_barrier_members_share_a_tag_and_say_whom_they_wait_on(gui: Gui) -> None:
    feed = gui.feed
    a, b, c = feed.add("alpha", "wait"), feed.add("bravo", "wait"), feed.add("charlie", "wait")
    feed("add_barrier", [a, b, c])
    tags = {
        gui.cell(agent, True, 0, TAG, Qt.DisplayRole) for agent in ("alpha", "bravo", "charlie")
    }
    assert tags == {"B1"}
    colours = {
        gui.cell(agent, True, 0, TAG, Qt.BackgroundRole).color().name()
        for agent in ("alpha", "bravo", "charlie")
    }
    assert colours == {p.barrier_colour(1)}
    for agent in ("alpha", "bravo", "charlie"):
        feed.sync(agent)
    feed("report_status", a, S.SYNCWAITING)
    assert gui.colour("alpha", False, 0) == p.STATUS_COLOURS[S.SYNCWAITING]
    assert gui.cell("alpha", False, 0, STATUS, Qt.DisplayRole) == "waiting on bravo, charlie"
    feed("report_status", b, S.SYNCWAITING)  # bravo arrives: alpha now waits on charlie only
    assert gui.cell("alpha", False, 0, STATUS, Qt.DisplayRole) == "waiting on charlie"
    assert gui.cell("bravo", False, 0, STATUS, Qt.DisplayRole) == "waiting on charlie"
    # What the robot itself reports wins: during a cut it knows what the ground cannot.
    reported = "charlie at B1 (arrived, not yet confirmed)"
    feed.statuses(AgentStatus("alpha", link="up", current_skill=a, waiting_on=reported))
    gui.app.processEvents()
    assert gui.cell("alpha", False, 0, STATUS, Qt.DisplayRole) == f"waiting on {reported}"
    assert gui.cell("bravo", False, 0, STATUS, Qt.DisplayRole) == "waiting on charlie"


def test_robot_headers_in_words() -> None:
    assert p.link_summary(None) == "never heard"
    up = AgentStatus("alpha", link="up", last_heard=0.3, battery=0.72, wifi_signal=-61.0)
    assert p.link_summary(up) == "link up · battery 72% · Wi-Fi out of range"
    inside = replace(up, in_coverage=True)
    assert p.link_summary(inside) == "link up · battery 72% · Wi-Fi fair"
    assert p.wifi_words(-50.0, True) == "good" and p.wifi_words(-76.0, True) == "weak"
    assert p.link_details(inside) == "Wi-Fi signal -61 dBm"
    down = AgentStatus("alpha", link="down", last_heard=42.0, in_coverage=True, wifi_signal=-90)
    assert p.link_summary(down).startswith("LINK DOWN, heard 42 s ago")
    held = replace(down, commands_waiting=2, waiting_for=130.0)
    assert p.link_summary(held).startswith(
        "LINK DOWN, heard 42 s ago · 2 commands waiting for contact 2 min · "
    )
    never = AgentStatus("alpha", commands_waiting=1, waiting_for=3.0)
    assert p.link_summary(never) == "never heard · 1 command waiting for contact 3 s"
