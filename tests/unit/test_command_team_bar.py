"""The command GUI with 20 robots on a 1600x1000 screen, driven with the mouse.

The real widget (offscreen Qt) follows a real 20-robot mission through a real mirror
(the unit harness). The operator scrolls the task panel sideways with the scroll bar, makes
the columns compact, and narrows the team by name, by ticking robots in the robot list
and by status; the test checks which columns are on screen after each click.
"""

from __future__ import annotations

import subprocess
import sys
from collections.abc import Iterator
from pathlib import Path

import pytest
from python_qt_binding.QtCore import Qt
from python_qt_binding.QtGui import QColor, QImage
from python_qt_binding.QtTest import QTest

from rosmc_rqt_command.core.presentation import STATUS_COLOURS
from rosmc_rqt_command.qt.agent_column import COLUMN_WIDTH, COMPACT_WIDTH
from rosmc_server.core import SkillStatus
from tests.team_gui import click, columns, on_screen, settle, step_right, team, tick
from tests.team_twenty import WAITING, Staged, stage, twenty_robot_library
from tests.unit.conftest import make_mission
from tests.unit.test_command_harness import Gui

REPO = Path(__file__).resolve().parents[2]
TOOL = REPO / "tools" / "command_gui_team_screenshot.py"


@pytest.fixture
def big() -> Iterator[tuple[Gui, Staged]]:
    """The command widget at 1600x1000 following the staged 20-robot mission."""
    library = twenty_robot_library()
    gui = Gui(make_mission(library), library)
    gui.widget.resize(1600, 1000)
    staged = stage(gui.feed)
    settle(gui.widget)
    yield gui, staged
    gui.close()


def test_every_robot_is_reachable_by_scrolling_at_a_readable_width(
    big: tuple[Gui, Staged],
) -> None:
    gui, staged = big
    assert list(columns(gui.widget)) == list(staged.robots)
    assert team(gui.widget).count.text() == "20 of 20 robots shown"
    first = on_screen(gui.widget)
    assert first[0] == "drone_1" and len(first) < len(staged.robots)
    seen = list(first)
    bar = gui.widget.tasks.horizontalScrollBar()
    while bar.value() < bar.maximum():
        before = bar.value()
        step_right(gui.widget)
        assert bar.value() > before, "a click on the scroll bar moves the task panel"
        seen += [agent for agent in on_screen(gui.widget) if agent not in seen]
    assert seen == list(staged.robots)
    assert all(c.width() >= COLUMN_WIDTH for c in columns(gui.widget).values())


def test_compact_mode_fits_more_columns_and_drops_cells(big: tuple[Gui, Staged]) -> None:
    gui, _staged = big
    wide = on_screen(gui.widget)
    click(gui.widget, "team_compact")
    compact = on_screen(gui.widget)
    assert len(compact) > len(wide)
    assert compact[: len(wide)] == wide
    for column in columns(gui.widget).values():
        assert column.width() >= COMPACT_WIDTH
        assert column.width() < COLUMN_WIDTH
        assert column.synced_table.isColumnHidden(1) and column.blueprint_table.isColumnHidden(4)
    click(gui.widget, "team_compact")  # and back
    assert on_screen(gui.widget) == wide
    assert not columns(gui.widget)["drone_1"].blueprint_table.isColumnHidden(4)


def test_filters_show_exactly_the_chosen_robots(big: tuple[Gui, Staged]) -> None:
    gui, staged = big
    bar = team(gui.widget)
    # By name: typed into the filter field.
    QTest.mouseClick(bar.text, Qt.LeftButton)
    QTest.keyClicks(bar.text, "science")
    settle(gui.widget)
    science = [f"science_rover_{n}" for n in range(1, 8)]
    assert bar.visible() == science
    assert on_screen(gui.widget) == science[: len(on_screen(gui.widget))]
    # By the robot list: untick two, tick one back.
    tick(gui.widget, "science_rover_2")
    tick(gui.widget, "science_rover_5")
    assert bar.visible() == [r for r in science if r not in ("science_rover_2", "science_rover_5")]
    tick(gui.widget, "science_rover_2")
    assert bar.visible() == [r for r in science if r != "science_rover_5"]
    assert bar.count.text() == "6 of 20 robots shown"
    # By status, with the name filter cleared.
    bar.text.clear()
    settle(gui.widget)
    click(gui.widget, "team_status_failed")
    assert bar.visible() == list(staged.failed)
    click(gui.widget, "team_status_out_of_contact")
    assert bar.visible() == list(staged.out_of_contact)
    click(gui.widget, "team_status_waiting")
    assert bar.visible() == WAITING
    click(gui.widget, "team_compact")
    assert on_screen(gui.widget) == bar.visible()  # compact, the four fit: no scrolling needed
    click(gui.widget, "team_compact")
    click(gui.widget, "team_status_all")
    assert bar.visible() == [r for r in staged.robots if r != "science_rover_5"]
    tick(gui.widget, "Show all robots")
    assert bar.visible() == list(staged.robots)
    assert gui.backend.requests == []  # filtering never changes the mission


def test_status_filter_follows_the_mission_live(big: tuple[Gui, Staged]) -> None:
    gui, _staged = big
    click(gui.widget, "team_status_failed")
    running = next(
        s for s in gui.widget.view.view("drone_4").skills if s.status is SkillStatus.RUNNING
    )
    gui.feed("report_status", running.id, SkillStatus.FAILURE, text="lost the horizon")
    settle(gui.widget)
    assert team(gui.widget).visible() == ["drone_2", "drone_4"]
    failed = next(
        s for s in gui.widget.view.view("drone_2").skills if s.status is SkillStatus.FAILURE
    )
    gui.feed("retry", failed.id)
    settle(gui.widget)
    assert team(gui.widget).visible() == ["drone_4"]


def row_pixels(picture: Path, status: SkillStatus) -> int:
    """Pixels of ``status``'s row colour above the colour key (the key has one swatch)."""
    image = QImage(str(picture))
    assert (image.width(), image.height()) == (1600, 1000)
    colour = QColor(STATUS_COLOURS[status]).rgb()
    legend_top = 940  # the colour key sits in the bottom rows of the window
    return sum(
        image.pixel(x, y) == colour for x in range(0, 1200, 2) for y in range(100, legend_top, 2)
    )


def test_the_documented_screenshot_commands_show_the_team(tmp_path: Path) -> None:
    """``tools/command_gui_team_screenshot.py`` as docs/operator-guide.md shows it, then filtered.

    All robots: the first columns hold the failed drone, the barrier waits are off screen.
    Waiting only: the rovers waiting at their barrier come on screen, the failed drone goes.
    """
    shots = {}
    for name, extra in (("all", []), ("waiting", ["--status", "waiting"])):
        shots[name] = tmp_path / f"{name}.png"
        subprocess.run(
            [sys.executable, str(TOOL), "--compact", *extra, "-o", str(shots[name])],
            check=True,
            cwd=REPO,
            capture_output=True,
            timeout=120,
        )
    waiting, failure = SkillStatus.SYNCWAITING, SkillStatus.FAILURE
    assert row_pixels(shots["all"], failure) > 0
    assert row_pixels(shots["all"], waiting) == 0
    assert row_pixels(shots["waiting"], waiting) > 0
    assert row_pixels(shots["waiting"], failure) == 0
