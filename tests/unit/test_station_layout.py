"""The station on one screen: rviz left, the command window right, and the mission clock.

The split of the screen is checked at three screen sizes, and the real command window
(offscreen Qt, the unit harness following the shipped team's mission, every warning at
once) is put at its share of each: it keeps that width, and its panels, the team bar and
the clock in the menu bar are whole inside it.
"""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

import pytest
import yaml
from python_qt_binding.QtWidgets import QMainWindow

from rosmc_rqt_command.core.station_layout import (
    MISSION,
    REPLAY,
    UTC,
    Rect,
    clock_text,
    rviz_config_at,
    split_screen,
)
from rosmc_rqt_command.qt.replay_bar import ReplayBar
from rosmc_rqt_command.qt.station_menu import StationHooks, StationMenu
from rosmc_server.core import Library
from rosmc_server.core.skills.library import load_library
from tests.team_gui import settle
from tests.unit.conftest import SHIPPED_LIBRARY, make_mission
from tests.unit.test_command_harness import Gui
from tests.unit.test_command_layout import ROBOTS, every_warning, inside

SCREENS = [(1280, 800), (1600, 1000), (1920, 1080)]
CONFIG = Path(__file__).resolve().parents[2] / "rviz" / "operator.rviz"


@pytest.mark.parametrize("size", SCREENS)
def test_the_two_windows_share_the_screen_without_overlap(size: tuple[int, int]) -> None:
    screen = Rect(0, 0, *size)
    station = split_screen(screen)
    assert not station.rviz.overlaps(station.command)
    assert station.rviz.right <= station.command.x
    for part in (station.rviz, station.command):
        assert part.x >= 0 and part.right <= size[0]
        assert part.y >= 0 and part.y + part.height <= size[1]
    assert station.command.right == size[0], "the command window reaches the right edge"
    assert 560 <= station.command.width <= station.rviz.width


def test_a_screen_too_narrow_for_two_windows_gives_each_all_of_it() -> None:
    station = split_screen(Rect(0, 0, 800, 600))
    assert station.rviz == station.command == Rect(0, 32, 800, 568)


def test_a_panel_on_the_left_moves_both_windows() -> None:
    station = split_screen(Rect(64, 0, 1536, 1000))  # a dock 64 px wide on the left
    assert station.rviz.x == 64 and station.command.right == 1600


def test_the_rviz_config_copy_changes_only_the_window_geometry() -> None:
    text = CONFIG.read_text(encoding="utf-8")
    place = Rect(0, 32, 844, 968)
    copy = yaml.safe_load(rviz_config_at(text, place))
    original = yaml.safe_load(text)
    geometry = copy.pop("Window Geometry")
    assert (geometry["X"], geometry["Y"], geometry["Width"], geometry["Height"]) == (
        0,
        32,
        844,
        968,
    )
    kept = original.pop("Window Geometry")
    assert copy == original
    numbers = ("X", "Y", "Width", "Height")
    rest = {k: v for k, v in geometry.items() if k not in numbers}
    assert rest == {k: v for k, v in kept.items() if k not in numbers}


def test_the_clock_reads_hours_minutes_and_seconds() -> None:
    assert clock_text(3723.9) == "mission time 1:02:03"
    assert clock_text(5.0, REPLAY) == "replay time 0:00:05"
    assert clock_text(None) == f"{MISSION} –:––:––"
    assert clock_text(86399.0, UTC) == "UTC 23:59:59"


@pytest.fixture(scope="module")
def shipped() -> Library:
    return load_library(SHIPPED_LIBRARY)


@pytest.fixture
def station_window(shipped: Library) -> Iterator[tuple[Gui, QMainWindow, StationMenu]]:
    """The command widget in a main window with the station's menu and clock."""
    gui = Gui(make_mission(shipped), shipped)
    main = QMainWindow()
    main.setCentralWidget(gui.widget)
    menu = StationMenu(gui.widget, StationHooks(lambda: "", lambda: (3723.0, MISSION)), main.close)
    main.show()
    for agent in ROBOTS:
        gui.feed.add(agent, "navigate_to")
    settle(gui.widget)
    yield gui, main, menu
    main.close()
    gui.close()


@pytest.mark.parametrize("size", SCREENS)
def test_the_command_window_is_whole_in_its_share_of_the_screen(
    station_window: tuple[Gui, QMainWindow, StationMenu], size: tuple[int, int]
) -> None:
    gui, main, menu = station_window
    share = split_screen(Rect(0, 0, *size)).command
    assert main.minimumSizeHint().width() <= share.width
    main.resize(share.width, share.height)
    settle(gui.widget)
    every_warning(gui)
    assert main.width() == share.width, "the window kept its share"
    widget = gui.widget
    for part in (widget.parameters, widget.control, widget.team, widget.messages):
        assert part.isVisible() and main.rect().contains(inside(main, part)), part
    warnings, box = widget.messages.warnings_label, widget.messages.warnings_box
    whole = box.viewport().height() >= warnings.heightForWidth(box.viewport().width())
    assert whole or box.verticalScrollBar().isVisible(), "every warning line is whole or scrolls"
    assert box.height() >= 3 * warnings.fontMetrics().lineSpacing(), "more than a line shows"
    assert widget.parameters.width() >= 300
    for name, button in widget.control.buttons.items():  # no button is cut short
        assert button.width() >= button.sizeHint().width(), name
    team = widget.team
    for child in (team.text, team.robots_button, team.compact, team.count):
        assert team.rect().contains(inside(team, child)), child.objectName()
    assert team.count.width() >= team.count.sizeHint().width(), team.count.text()
    bar = widget.findChild(ReplayBar)  # every_warning opened a recording's bar
    for button in (bar.play_button, bar.slower_button, bar.faster_button, bar.live_button):
        assert button.isVisible() and button.width() >= button.sizeHint().width(), button.text()
        assert main.rect().contains(inside(main, button)), button.text()
    assert bar.slider.width() >= 100, "the timeline has room"
    assert bar.title.width() >= 200, "the recording's name is not squeezed to a letter"
    assert menu.clock.text() == "mission time 1:02:03"
    assert menu.clock.isVisible() and menu.clock.width() >= menu.clock.sizeHint().width()
    assert main.rect().contains(inside(main, menu.clock))


def test_file_quit_closes_the_window_and_show_3d_view_says_what_it_did(
    station_window: tuple[Gui, QMainWindow, StationMenu],
) -> None:
    gui, main, menu = station_window
    said: list[str] = []
    menu.hooks = StationHooks(
        lambda: said.append("asked") or "Starting the 3D view (rviz).", menu.hooks.clock
    )
    file_menu = gui.widget.menu_bar.actions()[0].menu()
    assert menu.quit in file_menu.actions() and menu.quit.shortcut().toString() == "Ctrl+Q"
    menu.show_3d.trigger()
    assert said == ["asked"]
    assert any(m.endswith("Starting the 3D view (rviz).") for m in gui.widget.messages.messages())
    menu.quit.trigger()
    assert not main.isVisible()
