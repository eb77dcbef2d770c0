"""Editing that forgives, in the command GUI against a real mission server.

A real master and ``mission_server`` process, the real widget and ROS bridge
(offscreen Qt). The operator adds and deletes a skill with the mouse, takes the
delete back with Ctrl+Z, redoes it with Ctrl+Shift+Z, undoes through the Edit menu
with the mouse, and sees a refusal when another operator changed the skill since.
Closing with unsaved changes and choosing Save keeps the window open until the
save is confirmed, and says why when it fails.
"""

from __future__ import annotations

import os
from typing import Any

os.environ.setdefault("QT_QPA_PLATFORM", "offscreen")

from pathlib import Path

from python_qt_binding.QtCore import Qt
from python_qt_binding.QtTest import QTest
from python_qt_binding.QtWidgets import QApplication, QMenu

from rosmc_rqt_command.standalone import CommandWindow
from rosmc_server.ros.client import MissionClient
from tests.integration.server_fixtures import StartServer
from tests.integration.test_command_gui_server import (  # noqa: F401 (the fixture)
    Window,
    no_traceback,
    shown,
    wait_until,
    windows,
)

pytest_plugins = ["tests.integration.server_fixtures"]


def press(window: Window, key: int, modifiers: Any = Qt.ControlModifier) -> None:
    """A key press on the focused task panel of the active command window."""
    QApplication.setActiveWindow(window.w)
    target = QApplication.focusWidget() or window.w.tasks
    QTest.keyClick(target, key, modifiers)


def click_menu_item(window: Window, menu_title: str, item: str) -> None:
    """Open a menu of the menu bar with the mouse and click one of its items."""
    bar = window.w.menu_bar
    menu_action = next(a for a in bar.actions() if a.text().replace("&", "") == menu_title)
    QTest.mouseClick(bar, Qt.LeftButton, Qt.NoModifier, bar.actionGeometry(menu_action).center())
    menu: QMenu = wait_until(lambda: QApplication.activePopupWidget(), 10, "the menu open")
    action = next(a for a in menu.actions() if a.text().replace("&", "").startswith(item))
    assert action.isEnabled(), action.text()
    QTest.mouseClick(menu, Qt.LeftButton, Qt.NoModifier, menu.actionGeometry(action).center())


def test_undo_and_redo_with_keys_and_mouse(
    start_server: StartServer,
    windows: Any,  # noqa: F811 (the fixture imported above)
) -> None:
    start_server()
    window = windows()
    shown(window)
    window.add("drone", "take_off")
    window.said("Ctrl+Z undoes it")
    wait_until(lambda: len(window.ids("drone")) == 1, 10, "take_off shown")
    (take_off,) = window.ids("drone")
    window.click_row("drone", 0)
    QTest.mouseClick(window.w.control.buttons["delete"], Qt.LeftButton)
    deleted = window.said("Done: delete 'take_off'")
    assert "Ctrl+Z undoes it" in deleted, deleted
    wait_until(lambda: window.ids("drone") == [], 10, "the delete shown")

    press(window, Qt.Key_Z)
    window.said("Done: undo delete 'take_off'")
    wait_until(lambda: window.ids("drone") == [take_off], 10, "the skill back")
    press(window, Qt.Key_Z, Qt.ControlModifier | Qt.ShiftModifier)
    window.said("Done: redo delete 'take_off'")
    wait_until(lambda: window.ids("drone") == [], 10, "deleted again")
    press(window, Qt.Key_Z)
    wait_until(lambda: window.ids("drone") == [take_off], 10, "back again")

    # The mouse alone: Edit > Undo takes back the add, Edit > Redo brings it back.
    wait_until(lambda: window.w.history.undo_action.isEnabled(), 10, "undo possible")
    click_menu_item(window, "Edit", "Undo")
    wait_until(lambda: window.ids("drone") == [], 10, "the add undone")
    wait_until(lambda: window.w.history.redo_action.isEnabled(), 10, "redo possible")
    click_menu_item(window, "Edit", "Redo")
    wait_until(lambda: window.ids("drone") == [take_off], 10, "the add redone")

    # Another operator changes the skill: this window's undo is refused, nothing changes.
    client = MissionClient(5.0)
    try:
        client.get_mission()
        client.edit_skill(take_off, {"altitude": 23.0})
    finally:
        client.close()
    wait_until(
        lambda: window.w.view.skill(take_off).params["altitude"] == 23.0, 10, "the edit seen"
    )
    wait_until(lambda: window.w.history.undo_action.isEnabled(), 10, "undo possible")
    press(window, Qt.Key_Z)
    refused = window.said("Could not undo")
    assert f"skill '{take_off}' was changed since revision" in refused, refused
    assert window.ids("drone") == [take_off]
    assert window.w.view.skill(take_off).params["altitude"] == 23.0
    no_traceback(window)


def test_close_with_save_waits_for_the_save(
    start_server: StartServer,
    windows: Any,  # noqa: F811 (the fixture imported above)
    tmp_path: Path,
) -> None:
    start_server()
    window = windows()
    shown(window)
    main = CommandWindow(window.w, "ROSMC command")
    main.show()
    window.add("drone", "take_off")
    wait_until(lambda: window.ids("drone"), 10, "take_off shown")
    assert window.w.files.dirty
    window.w.files.ask = lambda doing: "save"  # the operator's answer to "Save them first?"

    # The first save cannot be written: the window stays open and says why.
    window.w.files.location = ("local", str(tmp_path / "no such folder" / "plan.yaml"))
    assert not main.close()
    assert main.isVisible()
    window.said("Cannot write")
    window.said("Not closed: the mission was not saved")
    assert main.isVisible()

    # Saved where it can be: the window closes once the save is confirmed, not before.
    target = tmp_path / "plan.yaml"
    window.w.files.location = ("local", str(target))
    assert not main.close()
    assert main.isVisible() and not target.exists()
    wait_until(lambda: not main.isVisible(), 10, "the window closed after the save")
    assert "take_off" in target.read_text()
    main.takeCentralWidget()  # the fixture closes the widget itself
