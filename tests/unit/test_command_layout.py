"""The command window keeps its width when warnings arrive, and no edit goes nowhere.

The real window (offscreen Qt) follows the shipped team's mission through the unit
harness. Warnings of every kind arrive at once (a robot leaving Wi-Fi, the server
restarting, a recording with a long name opened); the window must keep the width it has,
with the whole parameter panel inside it, at 1600x1000 and at smaller screens. The
splitter is dragged with the mouse, and an edit typed while its skill is sent to the robot
is said in the message area, not dropped.
"""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

import pytest
from python_qt_binding.QtCore import QEvent, QPoint, QRect, Qt
from python_qt_binding.QtGui import QMouseEvent
from python_qt_binding.QtTest import QTest
from python_qt_binding.QtWidgets import QApplication, QMainWindow

from rosmc_rqt_command.qt.replay_bar import ReplayBar
from rosmc_rqt_command.replay_ticks import RecordingOutline
from rosmc_server.core import (
    AgentStatus,
    Library,
    LostLinkKind,
    LostLinkPolicy,
    LostLinkTrigger,
    PolicyInForce,
)
from rosmc_server.core.skills.library import load_library
from tests.team_gui import settle
from tests.unit.conftest import SHIPPED_LIBRARY, make_mission
from tests.unit.test_command_harness import Gui

ROBOTS = ("drone", "science_rover", "manipulator_rover")
LONG_POLICY = PolicyInForce(
    LostLinkPolicy(LostLinkKind.RETURN_TO_LINK, 60.0, "navigate_to", when=LostLinkTrigger.IDLE),
    acted="returning to the last link position (18.9, -1.0) after 68 s without ground contact; "
    "ground contact is back (done); holding",
)
LONG_NAME = "/home/operator/recordings/" + "mars_sample_return_2024_06_30_" * 4 + ".mcap"


@pytest.fixture(scope="module")
def shipped() -> Library:
    """The Mars team library."""
    return load_library(SHIPPED_LIBRARY)


@pytest.fixture
def window(shipped: Library) -> Iterator[tuple[Gui, QMainWindow]]:
    """The command widget in a main window, one planned skill per robot."""
    gui = Gui(make_mission(shipped), shipped)
    main = QMainWindow()
    main.setCentralWidget(gui.widget)
    main.show()
    for agent in ROBOTS:
        gui.feed.add(agent, "navigate_to")
    settle(gui.widget)
    yield gui, main
    main.close()
    gui.close()


def every_warning(gui: Gui) -> None:
    """Everything that once made the window wider than the screen, at once."""
    widget = gui.widget
    gui.feed.statuses(
        *(
            AgentStatus(
                agent,
                link="down",
                last_heard=12,
                battery=0.5,
                wifi_signal=-80.0,
                executor_state="paused",
                lost_link=LONG_POLICY,
                coverage_warning="its synchronized task ends at (30.0, -16.0), out of radio "
                "coverage, and its policy on link loss: continue would leave it there",
                commands_waiting=2,
                waiting_for=5,
            )
            for agent in ROBOTS
        )
    )
    widget.on_server_restarted(626)
    widget.on_connection(False)
    widget.messages.say(f"Replaying {LONG_NAME} (12.0 s), paused at the start", "info")
    bar = ReplayBar()
    widget.layout().insertWidget(1, bar)
    bar.set_outline(RecordingOutline(Path(LONG_NAME), 12.0, ()))
    settle(widget)
    widget.repaints.warn_now()
    widget.messages.show_warnings([*widget.messages.warnings, f"Cannot replay {LONG_NAME}"])
    settle(widget)


def inside(main: QMainWindow, child: object) -> QRect:
    """``child``'s rectangle in ``main``'s coordinates."""
    top_left = child.mapTo(main, QPoint(0, 0))  # type: ignore[attr-defined]
    return QRect(top_left, child.size())  # type: ignore[attr-defined]


@pytest.mark.parametrize("size", [(1600, 1000), (1280, 800)])
def test_warnings_never_widen_the_window_nor_push_the_parameters_off(
    window: tuple[Gui, QMainWindow], size: tuple[int, int]
) -> None:
    gui, main = window
    main.resize(*size)
    settle(gui.widget)
    every_warning(gui)
    assert gui.widget.messages.warnings, "the warnings are shown"
    assert main.width() == size[0], "the window kept its width"
    assert main.minimumSizeHint().width() <= 1200
    panel = gui.widget.parameters
    assert panel.isVisible() and panel.width() >= 300
    assert main.rect().contains(inside(main, panel)), "the whole parameter panel is on screen"
    control = gui.widget.control
    assert main.rect().contains(inside(main, control))
    for name, button in control.buttons.items():  # no button is cut short
        assert button.width() >= button.sizeHint().width(), name
    live = gui.widget.findChild(ReplayBar).live_button
    assert live.isVisible() and live.width() >= live.sizeHint().width()  # "Return to live"


def test_the_splitter_drags_both_ways_and_never_hides_the_parameters(
    window: tuple[Gui, QMainWindow],
) -> None:
    gui, main = window
    main.resize(1600, 1000)
    every_warning(gui)
    splitter = gui.widget.splitter
    handle = splitter.handle(1)
    panel = gui.widget.parameters

    def drag(dx: int) -> None:
        centre = handle.rect().center()
        QTest.mousePress(handle, Qt.LeftButton, Qt.NoModifier, centre)
        # QTest.mouseMove carries no button in Qt 5: a drag is a move with the button held.
        to = centre + QPoint(dx, 0)
        move = QMouseEvent(QEvent.MouseMove, to, Qt.NoButton, Qt.LeftButton, Qt.NoModifier)
        QApplication.sendEvent(handle, move)
        QTest.mouseRelease(handle, Qt.LeftButton, Qt.NoModifier, to)
        settle(gui.widget)

    before = panel.width()
    drag(-80)  # to the left: the parameters get wider
    assert panel.width() > before
    drag(2000)  # far to the right: they narrow to their minimum, never to nothing
    assert panel.isVisible() and panel.width() >= 300
    assert main.rect().contains(inside(main, panel))
    assert main.width() == 1600


def test_an_edit_typed_while_its_skill_is_sent_is_said_not_lost(
    window: tuple[Gui, QMainWindow],
) -> None:
    gui, main = window
    main.resize(1600, 1000)
    widget = gui.widget
    gui.click_row("science_rover", True, 0)
    spin = widget.parameters.editors["target"].spins["x"]  # type: ignore[attr-defined]
    spin.setFocus()
    spin.lineEdit().selectAll()
    QTest.keyClicks(spin.lineEdit(), "12.5")
    gui.feed.sync("science_rover")  # sent by someone else while the operator types
    settle(widget)
    QTest.keyClick(spin.lineEdit(), Qt.Key_Return)
    QApplication.processEvents()
    said = widget.messages.messages()
    assert any("Not sent: 'navigate_to' on science_rover is no longer planned" in m for m in said)
    assert gui.backend.operations() == []  # nothing was sent for the edit
    skill = widget.view.skill(gui.ids("science_rover", False)[0])
    assert spin.value() == skill.params["target"].x != 12.5  # the skill's value again


def test_the_label_field_is_not_left_pink_after_the_selection_is_cleared(
    window: tuple[Gui, QMainWindow],
) -> None:
    gui, _main = window
    widget = gui.widget
    gui.click_row("drone", True, 0)
    field = widget.parameters.label_edit
    QTest.mouseClick(field, Qt.LeftButton)
    field.selectAll()
    QTest.keyClick(field, Qt.Key_Delete)
    QTest.keyClick(field, Qt.Key_Return)  # an empty label is refused and tinted
    assert "background" in field.styleSheet()
    QTest.keyClick(gui.table("drone", True).viewport(), Qt.Key_Escape)
    widget.tasks.clear_selection()
    assert widget.parameters.skill is None
    assert field.styleSheet() == ""
