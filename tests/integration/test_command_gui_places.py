"""Places and duplicating in the command GUI, driven with the mouse and keys like an operator.

Real master, real mission server with the Mars library, the real widget offscreen. The
science a simulator publishes (a discovered region) is published on its real topic. After
each step the test asserts what the server's mission holds.
"""

from __future__ import annotations

import os
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest

os.environ.setdefault("QT_QPA_PLATFORM", "offscreen")

import rospy
from python_qt_binding.QtCore import QPoint, Qt
from python_qt_binding.QtGui import QPainter
from python_qt_binding.QtTest import QTest
from python_qt_binding.QtWidgets import QApplication

from rosmc_rqt_command.qt.place_picker import NEW_MARKER, PICK_IN_VIEW, PlacePicker
from rosmc_rqt_command.standalone import build
from rosmc_server import interface
from rosmc_server.conversions.science import science_to_msg
from rosmc_server.core import MarkerType, Pose, TaskMarker
from rosmc_server.core.views.science import RegionScience, Science
from rosmc_server.ros.client import MissionClient
from tests.integration.executor_fixtures import Operator, RosmcSystem, init_test_node
from tests.integration.test_command_gui import Gui, wait_until

REPO = Path(__file__).resolve().parents[2]
LIBRARY = REPO / "rosmc_server" / "config" / "mars_team.yaml"
RSS_A = RegionScience("RSS A", 16.0, 9.0, 3.0, 1.0, 3, "")
PICTURE = os.environ.get("ROSMC_PLACES_PICTURE", "")  # where to write the docs' picture


@pytest.fixture
def mars(ros_master: Any, tmp_path: Path) -> Iterator[tuple[Operator, Gui, MissionClient]]:
    """The mission server with the Mars library, science published, the widget following."""
    system = RosmcSystem(ros_master.env, tmp_path / "system", LIBRARY)
    system.start_server()
    init_test_node()
    science = rospy.Publisher(
        interface.SCIENCE_TOPIC,
        science_to_msg(Science(0.0, 0, ())).__class__,
        latch=True,
        queue_size=1,
    )
    published = science_to_msg(Science(0.0, 0, (RSS_A,)))
    operator = Operator()
    client = MissionClient(5.0)
    app = QApplication.instance() or QApplication([])
    widget, bridge = build(timeout=30.0)
    widget.resize(1500, 1000)
    widget.show()
    widget.activateWindow()  # shortcuts need an active window
    QTest.qWaitForWindowActive(widget, 2000)
    wait_until(lambda: widget.view.loaded and widget.view.library, 60, "the mission is shown")
    # Published until heard: a subscriber in this process may connect after a latched send.
    wait_until(
        lambda: science.publish(published) or widget.science.science is not None,
        30,
        "the science is shown",
    )
    try:
        yield operator, Gui(widget, bridge), client
    finally:
        widget.tasks.clear_selection()  # said to rviz while the bridge is open
        app.processEvents()
        bridge.close()
        widget.close()
        widget.deleteLater()
        app.processEvents()
        science.unregister()
        client.close()
        operator.close()
        system.close()


def open_list(picker: PlacePicker) -> Any:
    """Click the picker's arrow; the list that opens."""
    QTest.mouseClick(picker, Qt.LeftButton, Qt.NoModifier, QPoint(picker.width() - 8, 10))
    view = picker.view()
    wait_until(lambda: view.isVisible(), 10, "the list open")
    return view


def choose(picker: PlacePicker, text: str) -> None:
    """Open the picker's list and click the entry that starts with ``text``."""
    view = open_list(picker)
    row = next(i for i in range(picker.count()) if picker.itemText(i).startswith(text))
    rect = view.visualRect(picker.model().index(row, 0))

    def click() -> bool:
        # A list ignores the release of the click that opened it for a double-click
        # interval: click again until the list takes it.
        if view.isVisible():
            QTest.mouseClick(view.viewport(), Qt.LeftButton, Qt.NoModifier, rect.center())
        return not view.isVisible()

    wait_until(click, 10, "the list closed")


def shown_picker(gui: Gui, skill_id: str, param: str) -> PlacePicker:
    w = gui.widget
    wait_until(lambda: w.parameters.skill and w.parameters.skill.id == skill_id, 30, "shown")
    return wait_until(lambda: w.parameters.pickers.get(param), 30, f"the {param} picker")


def write_picture(gui: Gui, picker: PlacePicker, path: str) -> None:
    """The window with ``picker``'s list open, as the docs show it."""
    gui.widget.splitter.setSizes([880, 620])  # the parameters wide enough to read
    QApplication.processEvents()
    gui.widget.parameters.ensureWidgetVisible(gui.widget.parameters.places.drive_button)
    gui.widget.parameters.ensureWidgetVisible(picker)
    view = open_list(picker)
    shot = gui.widget.grab()
    popup = view.window()
    painter = QPainter(shot)
    # Drawn under the picker, where a screen large enough shows it (the offscreen screen
    # is smaller than the window and pushes the list inside it).
    painter.drawPixmap(picker.mapTo(gui.widget, QPoint(0, picker.height())), popup.grab())
    painter.end()
    assert shot.save(path)
    picker.hidePopup()


def test_places_are_picked_by_name_and_drive_there_first_is_offered(mars: Any) -> None:
    operator, gui, client = mars
    w = gui.widget
    rock = client.add_task_marker(TaskMarker("rock", MarkerType.POSITION, Pose(7.0, 8.0)))  # rviz
    wait_until(lambda: w.view.revision >= rock.revision, 30, "the rock shown")

    # A move, then a place picked by name with the mouse: bound to the marker.
    drive = gui.add("science_rover", "navigate_to")
    target = shown_picker(gui, drive, "target")
    wait_until(lambda: target.index_of("rock") > 0, 30, "rock offered")
    assert [target.index_of(n) > 0 for n in ("RSS A", "lander")] == [True, True]
    choose(target, "rock")
    wait_until(
        lambda: operator.mission().skill(drive).bindings.get("target") == "rock", 30, "bound"
    )
    assert operator.mission().skill(drive).params["target"].x == pytest.approx(7.0)
    wait_until(lambda: w.view.skill(drive).bindings, 30, "the binding shown")

    # A new skill there takes the robot's latest place, bound to the same marker; no
    # drive is offered (the robot goes there already).
    identify = gui.add("science_rover", "identify_stones")
    assert operator.mission().skill(identify).bindings == {"position": "rock"}
    shown_picker(gui, identify, "position")
    assert not w.parameters.places.drive_button.isVisibleTo(w)

    # A region picked for the manipulator rover's pick: the value, then drive there first.
    pick = gui.add("manipulator_rover", "pick_stone")
    position = shown_picker(gui, pick, "position")
    choose(position, "RSS A")
    wait_until(lambda: operator.mission().skill(pick).params["position"].x == 16.0, 30, "RSS A")
    assert operator.mission().skill(pick).params["position"].y == pytest.approx(9.0)
    button = w.parameters.places.drive_button
    wait_until(lambda: button.isVisibleTo(w) and "(16.0, 9.0)" in button.text(), 30, "offered")
    assert button.text() == "Drive there first: navigate_to to (16.0, 9.0) before pick_stone"
    if PICTURE:
        write_picture(gui, shown_picker(gui, pick, "position"), PICTURE)
    QTest.mouseClick(button, Qt.LeftButton)
    wait_until(lambda: len(operator.mission().task("manipulator_rover")) == 2, 30, "drive added")
    moved, picked = operator.mission().task("manipulator_rover")
    assert (moved.skill, picked.id) == ("navigate_to", pick)  # just before the pick
    assert (moved.params["target"].x, moved.params["target"].y) == (16.0, 9.0)
    wait_until(lambda: not button.isVisibleTo(w), 30, "no longer offered")

    # New marker here: a marker at the pick's place, bound at once.
    choose(shown_picker(gui, pick, "position"), NEW_MARKER)
    wait_until(lambda: operator.mission().skill(pick).bindings.get("position"), 30, "new marker")
    name = operator.mission().skill(pick).bindings["position"]
    marker = operator.mission().marker(name)
    assert (marker.type, marker.pose.x, marker.pose.y) == (MarkerType.POSITION, 16.0, 9.0)

    # Typed coordinates: unbound, the value stays.
    gui.click_row("science_rover", True, 0)
    choose(shown_picker(gui, drive, "target"), "Typed coordinates")
    wait_until(lambda: not operator.mission().skill(drive).bindings, 30, "unbound")
    assert operator.mission().skill(drive).params["target"].x == pytest.approx(7.0)

    # Pick in 3D view: the next task marker made (rviz's 2D Nav Goal makes it) is bound.
    choose(shown_picker(gui, drive, "target"), PICK_IN_VIEW)
    gui.said("the new marker fills target")
    client.add_task_marker(
        TaskMarker("goal", MarkerType.POSE, Pose(3.0, 4.0)), retry_on_conflict=True
    )
    wait_until(lambda: operator.mission().skill(drive).bindings == {"target": "goal"}, 30, "goal")
    assert operator.mission().skill(drive).params["target"].x == pytest.approx(3.0)


def test_duplicate_copies_the_selection_after_it_with_its_bindings(mars: Any) -> None:
    operator, gui, client = mars
    w = gui.widget
    rock = client.add_task_marker(TaskMarker("rock", MarkerType.POSITION, Pose(7.0, 8.0)))
    wait_until(lambda: w.view.revision >= rock.revision, 30, "the rock shown")
    drive = gui.add("manipulator_rover", "navigate_to")
    choose(shown_picker(gui, drive, "target"), "rock")
    wait_until(lambda: w.view.skill(drive).bindings.get("target"), 30, "bound")
    pick = gui.add("manipulator_rover", "pick_stone")  # at rock: the latest place
    deposit = gui.add("manipulator_rover", "deposit_at_lander")
    assert operator.mission().skill(pick).bindings == {"position": "rock"}

    # Select the three with the mouse, then Ctrl+D: the cycle once more, after it.
    gui.click_row("manipulator_rover", True, 0)
    gui.click_row("manipulator_rover", True, 1, Qt.ShiftModifier)
    gui.click_row("manipulator_rover", True, 2, Qt.ControlModifier)
    assert w.tasks.selected_ids == [drive, pick, deposit]
    QTest.keyClick(gui.table("manipulator_rover", True), Qt.Key_D, Qt.ControlModifier)
    wait_until(lambda: len(operator.mission().task("manipulator_rover")) == 6, 30, "copied")
    task = operator.mission().task("manipulator_rover")
    assert [s.skill for s in task] == ["navigate_to", "pick_stone", "deposit_at_lander"] * 2
    assert [s.id for s in task[:3]] == [drive, pick, deposit]
    assert task[3].bindings == {"target": "rock"} and task[4].bindings == {"position": "rock"}
    assert task[4].params == operator.mission().skill(pick).params
    copies = [s.id for s in task[3:]]
    wait_until(lambda: w.tasks.selected_ids == copies, 30, "the copies selected")

    # One Ctrl+Z takes every copy back; redo brings them all again.
    undo = w.history.undo_action
    wait_until(lambda: undo.text() == "&Undo duplicate 3 skills on manipulator_rover", 30, "one")
    table = gui.table("manipulator_rover", True)
    QTest.keyClick(table, Qt.Key_Z, Qt.ControlModifier)
    wait_until(lambda: len(operator.mission().task("manipulator_rover")) == 3, 30, "undone")
    assert [s.id for s in operator.mission().task("manipulator_rover")] == [drive, pick, deposit]
    wait_until(lambda: w.history.redo_action.isEnabled(), 30, "redo possible")
    QTest.keyClick(table, Qt.Key_Z, Qt.ControlModifier | Qt.ShiftModifier)
    wait_until(lambda: len(operator.mission().task("manipulator_rover")) == 6, 30, "redone")
    task = operator.mission().task("manipulator_rover")
    assert [s.skill for s in task] == ["navigate_to", "pick_stone", "deposit_at_lander"] * 2
    assert task[4].bindings == {"position": "rock"}

    # The context menu's Duplicate copies one skill right after it.
    gui.click_row("manipulator_rover", True, 1)
    gui.context_menu_choose("manipulator_rover", True, 1, "Duplicate")
    wait_until(lambda: len(operator.mission().task("manipulator_rover")) == 7, 30, "one more")
    task = operator.mission().task("manipulator_rover")
    assert [s.skill for s in task[:3]] == ["navigate_to", "pick_stone", "pick_stone"]
    assert task[2].bindings == {"position": "rock"}

    # Moving the marker moves every copy bound to it.
    client.move_task_marker("rock", Pose(9.0, 8.0), retry_on_conflict=True)
    assert all(
        s.params[p].x == 9.0
        for s in operator.mission().task("manipulator_rover")
        for p in s.bindings
    )
