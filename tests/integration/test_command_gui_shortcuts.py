"""The command GUI's keyboard shortcuts, pressed in a real window on a real X server.

Shortcuts fire only in an active window, and offscreen Qt never activates one; so this
test starts ``Xvfb`` and runs the window in a child process on it (``QT_QPA_PLATFORM``
xcb). The child is fed by a real :class:`~rosmc_server.core.Mission` through a real
mirror (the unit harness); it presses each shortcut docs/operator-guide.md lists on the
focused table and prints, as JSON, which request each key press sent. No ROS master is needed.
"""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
import time
from pathlib import Path
from typing import Any

import pytest

REPO = Path(__file__).resolve().parents[2]
CHILD = "from tests.integration.test_command_gui_shortcuts import drive; drive()"


def test_shortcuts_fire_in_a_real_window(tmp_path: Path) -> None:
    if shutil.which("Xvfb") is None and os.environ.get("CI"):
        pytest.fail("Xvfb is not installed under CI (make setup installs it)")
    if shutil.which("Xvfb") is None:
        pytest.skip("Xvfb is not installed (make setup installs it)")
    from tools.rviz_screenshot import virtual_screen

    with virtual_screen(1280, 900) as display:
        env = {**os.environ, "DISPLAY": display, "QT_QPA_PLATFORM": "xcb"}
        env["ROSMC_SHORTCUT_FILE"] = str(tmp_path / "saved.yaml")
        result = subprocess.run(
            [sys.executable, "-c", CHILD],
            env=env,
            cwd=REPO,
            stdin=subprocess.DEVNULL,
            capture_output=True,
            text=True,
            timeout=90,
            check=False,
        )
    assert result.returncode == 0, f"{result.stdout[-3000:]}\n{result.stderr[-3000:]}"
    pressed: dict[str, Any] = json.loads(result.stdout.strip().splitlines()[-1])
    assert pressed == {
        "active": True,
        "Delete": [["delete_skills", [["alpha-3"]]]],
        "Alt+Up": [["reorder_skills", ["alpha", ["alpha-2", "alpha-1", "alpha-4"]]]],
        "Ctrl+Up": [["reorder_skills", ["alpha", ["alpha-2", "alpha-1", "alpha-4"]]]],
        "Ctrl+Down": [["reorder_skills", ["alpha", ["alpha-1", "alpha-4", "alpha-2"]]]],
        "Ctrl+Return": [["synchronize", ["alpha", "alpha-2"]]],
        "Ctrl+B": [["add_barrier", [["alpha-1", "bravo-5"]]]],
        "Ctrl+Shift+B": [["delete_barrier", ["barrier-6"]]],
        "Ctrl+Backspace": [["unsynchronize", ["alpha", "alpha-1"]]],
        "Ctrl+R": [["retry_skill", ["alpha-1"]]],
        "Ctrl+K": [["skip_skill", ["alpha-1"]]],
        "F4": [["synchronize_team", [{"alpha": None, "bravo": None}]]],
        "F6": [["control", ["START", None]]],
        "F7": [["control", ["PAUSE", None]]],
        "F8": [["control", ["RESUME", None]]],
        "F9": [["control", ["STOP", None]]],
        "Ctrl+S": [["save_mission", []]],
        "Ctrl+O": "Open mission file",
        "Ctrl+Shift+O": "Open file on server",
        "Ctrl+Shift+S": "Save mission file",
        "Ctrl+Alt+S": "Save on server",
        "Ctrl+N": "asked: starting a new mission",
        "F5": "refreshed",
        "Escape": [],
        "Ctrl+Z": [["undo_edit", [41]]],
        "Ctrl+Shift+Z": [["undo_edit", [42]]],
    }


# -- the child process (runs on the X server) --------------------------------------------
def drive() -> None:
    """Press every shortcut in a real window; print what each sent as JSON."""
    import copy
    from types import SimpleNamespace

    from python_qt_binding.QtCore import Qt, QTimer
    from python_qt_binding.QtGui import QKeySequence
    from python_qt_binding.QtTest import QTest

    from rosmc_rqt_command.core.legality import RobotAction
    from rosmc_rqt_command.core.requests import Answer, ask
    from rosmc_server.core import AgentStatus, SkillStatus
    from rosmc_server.core.live.edit_history import EditKind
    from rosmc_server.core.skills.library import library_from_dict
    from tests.unit.conftest import TEST_LIBRARY, make_mission
    from tests.unit.test_command_harness import Gui

    library = library_from_dict(copy.deepcopy(TEST_LIBRARY), "unit_team.yaml")
    gui = Gui(make_mission(library), library)
    widget, feed, backend = gui.widget, gui.feed, gui.backend
    widget.activateWindow()
    active = QTest.qWaitForWindowActive(widget, 5000)
    alpha = [feed.add("alpha", "wait") for _ in range(3)]  # alpha-1..3
    report: dict[str, Any] = {"active": bool(active)}

    def press(keys: str) -> list[list[Any]]:
        """Press ``keys`` on the focused widget; the requests it sent."""
        backend.requests.clear()
        sequence = QKeySequence(keys)
        combined = sequence[0]
        key = combined & ~int(Qt.KeyboardModifierMask)
        modifiers = Qt.KeyboardModifiers(combined & int(Qt.KeyboardModifierMask))
        target = gui.app.focusWidget() or widget
        QTest.keyClick(target, key, modifiers)
        gui.app.processEvents()
        sent = [[r.operation, [getattr(a, "name", a) for a in r.args]] for r in backend.requests]
        report[keys] = sent
        return sent

    def until(condition: Any, timeout: float = 5.0) -> None:
        deadline = time.monotonic() + timeout
        while not condition():
            if time.monotonic() > deadline:
                raise AssertionError(f"timed out waiting for {condition}")
            QTest.qWait(20)

    def select(agent: str, row: int, blueprint: bool = True, extend: bool = False) -> None:
        gui.click_row(agent, blueprint, row, Qt.ControlModifier if extend else Qt.NoModifier)
        gui.table(agent, blueprint).setFocus()

    select("alpha", 2)
    press("Delete")
    feed("delete_skills", [alpha[2]])
    alpha.append(feed.add("alpha", "wait"))  # alpha-4
    select("alpha", 1)
    press("Alt+Up")
    press("Ctrl+Up")
    press("Ctrl+Down")
    press("Ctrl+Return")
    bravo = feed.add("bravo", "wait")  # bravo-5
    select("alpha", 0)
    select("bravo", 0, extend=True)
    press("Ctrl+B")
    feed("add_barrier", [alpha[0], bravo])  # barrier-6
    press("Ctrl+Shift+B")
    feed("delete_barrier", "barrier-6")
    widget.dispatcher.confirm_team = lambda text, warnings: True  # the one question: Yes
    press("F4")
    feed.sync("alpha", alpha[0])
    select("alpha", 0, blueprint=False)
    press("Ctrl+Backspace")
    feed("report_status", alpha[0], SkillStatus.RUNNING)
    feed("report_status", alpha[0], SkillStatus.FAILURE)
    press("Ctrl+R")
    press("Ctrl+K")
    # Every robot at once: bravo starts, runs, pauses (robot reports reach the buttons).
    feed.sync("bravo")
    press("F6")
    for state, status, key in (
        ("running", SkillStatus.RUNNING, "F7"),
        ("paused", SkillStatus.PAUSED, "F8"),
    ):
        feed.statuses(AgentStatus("bravo", link="up", executor_state=state))
        feed("report_status", bravo, status)
        action = widget.actions_.all_robots[
            RobotAction.PAUSE if key == "F7" else RobotAction.RESUME
        ]
        until(action.isEnabled)
        press(key)
    press("F9")
    widget.files.location = ("local", os.environ["ROSMC_SHORTCUT_FILE"])
    press("Ctrl+S")
    asked: list[str] = []
    widget.files.ask = lambda doing: asked.append(doing) or "cancel"
    if not press("Ctrl+N"):
        report["Ctrl+N"] = f"asked: {asked[0]}" if asked else "not asked"
    refreshes = backend.refreshes
    press("F5")
    report["F5"] = "refreshed" if backend.refreshes == refreshes + 1 else "not refreshed"
    press("Escape")
    if widget.tasks.selected_ids:
        report["Escape"] = ["still selected", widget.tasks.selected_ids]
    # The file dialogs: each key opens its dialog (closed again with Escape).
    widget.files.ask = lambda doing: "discard"
    for keys in ("Ctrl+O", "Ctrl+Shift+O", "Ctrl+Shift+S", "Ctrl+Alt+S"):
        titles: list[str] = []

        def close_dialog(titles: list[str] = titles) -> None:
            dialog = gui.app.activeModalWidget()
            if dialog is None:
                QTimer.singleShot(20, close_dialog)
                return
            titles.append(dialog.windowTitle())
            dialog.reject()

        QTimer.singleShot(20, close_dialog)
        widget.activateWindow()  # back from the last dialog
        QTest.qWaitForWindowActive(widget, 5000)
        gui.table("alpha", True).setFocus()
        press(keys)
        report[keys] = titles[0] if titles else "no dialog"
    # Undo and redo: an edit of this window the server accepted (revision 41), then the
    # answer to its undo (revision 42), which redo undoes in turn.
    for request in backend.requests:
        widget.on_answer(Answer(request, error="not served here"))
    deleted = ask(lambda c: c.delete_skills, "delete", kind=EditKind.DELETE_SKILLS)([alpha[1]])
    widget.on_answer(Answer(deleted, value=SimpleNamespace(revision=41)))
    widget.activateWindow()
    QTest.qWaitForWindowActive(widget, 5000)
    gui.table("alpha", True).setFocus()
    press("Ctrl+Z")
    for request in backend.requests:
        widget.on_answer(Answer(request, value=SimpleNamespace(revision=42)))
    press("Ctrl+Shift+Z")
    for request in backend.requests:
        widget.on_answer(Answer(request, error="not served here"))
    print(json.dumps(report))
    gui.close()
