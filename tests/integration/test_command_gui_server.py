"""The command GUI when the mission server is gone, slow or restarted; two windows; files;
sending the whole team's tasks with the mouse; the science score in view.

A real master and real ``mission_server`` processes; the real widget and ROS bridge
(offscreen Qt). While the server is stopped (or frozen with SIGSTOP) the operator keeps
clicking: every action must end as a readable sentence, the window must keep
answering (the longest gap between 10 ms timer ticks is measured), and the view must
come back when a server does.
"""

from __future__ import annotations

import os
import signal
import threading
import time
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import pytest
import rosmc.msg as wire
import rospy

os.environ.setdefault("QT_QPA_PLATFORM", "offscreen")

from python_qt_binding.QtCore import Qt, QTimer
from python_qt_binding.QtTest import QTest
from python_qt_binding.QtWidgets import (
    QApplication,
    QDialogButtonBox,
    QFileDialog,
    QLineEdit,
    QMessageBox,
)

from rosmc_rqt_command.core.legality import Action, RobotAction
from rosmc_rqt_command.qt.command_widget import CommandWidget
from rosmc_rqt_command.qt.science_strip import NO_SCORE
from rosmc_rqt_command.qt.site_strip import NO_SITE
from rosmc_rqt_command.qt.task_model import STATUS
from rosmc_rqt_command.standalone import build
from rosmc_server.conversions.science import science_to_msg
from rosmc_server.conversions.site import site_to_msg
from rosmc_server.core import LostLinkKind, LostLinkPolicy
from rosmc_server.core.views.science import RegionScience, Science
from rosmc_server.core.world.site import Footprint, Shape, SiteModel
from rosmc_server.interface import SCIENCE_TOPIC, SITE_TOPIC
from rosmc_server.ros.client import MissionClient
from tests import conftest
from tests.integration.server_fixtures import ServerProcess, StartServer

pytest_plugins = ["tests.integration.server_fixtures"]


def wait_until(condition: Callable[[], Any], timeout: float, what: str) -> Any:
    """Run the Qt event loop until ``condition()`` is truthy; fail after ``timeout``."""
    return conftest.wait_until(condition, timeout, what, pause=conftest.qt_pause)


class Heartbeat:
    """A 10 ms timer on the GUI thread: it ticks only while the event loop runs.

    The longest stall in milliseconds is ``bench/bench_command_gui.py``'s figure; a test
    checks the order: the loop ticks while a call to the server is outstanding.
    """

    def __init__(self) -> None:
        self.ticks = 0
        self.timer = QTimer()
        self.timer.timeout.connect(self._tick)
        self.timer.start(10)

    def _tick(self) -> None:
        self.ticks += 1

    def stop(self) -> None:
        self.timer.stop()


class Window:
    """One command window (widget + its own bridge) and the operator's hands."""

    def __init__(self, timeout: float = 2.0) -> None:
        self.widget, self.bridge = build(timeout=timeout)
        self.widget.resize(1400, 800)
        self.widget.show()

    @property
    def w(self) -> CommandWidget:
        return self.widget

    def ids(self, agent: str) -> list[str]:
        return [s.id for s in self.widget.view.view(agent).skills]

    def add(self, agent: str, skill: str) -> None:
        column = self.widget.tasks.columns[agent]
        next(a for a in column.add_menu.actions() if a.text() == skill).trigger()

    def click_row(self, agent: str, row: int, blueprint: bool = True) -> None:
        column = self.widget.tasks.columns[agent]
        table = column.blueprint_table if blueprint else column.synced_table
        rect = table.visualRect(table.section.index(row, 2))
        QTest.mouseClick(table.viewport(), Qt.LeftButton, Qt.NoModifier, rect.center())

    def said(self, fragment: str, timeout: float = 30.0) -> str:
        return str(
            wait_until(
                lambda: next((m for m in self.widget.messages.messages() if fragment in m), None),
                timeout,
                f"a message with {fragment!r}",
            )
        )

    def close(self) -> None:
        self.bridge.close()
        self.widget.close()
        self.widget.deleteLater()


@pytest.fixture
def windows(client_node: Any) -> Iterator[Callable[[], Window]]:
    """``windows()`` opens a command window; all are closed after the test."""
    app = QApplication.instance() or QApplication([])
    opened: list[Window] = []

    def open_window(timeout: float = 2.0) -> Window:
        window = Window(timeout)
        opened.append(window)
        return window

    yield open_window
    for window in opened:
        window.close()
    app.processEvents()


def shown(window: Window, timeout: float = 20.0) -> None:
    """The window shows a mission and knows the skill library."""
    wait_until(
        lambda: window.w.view.loaded and window.w.view.library and window.w.tasks.columns,
        timeout,
        "the mission is shown",
    )


def meanwhile(work: Callable[[], Any], timeout: float = 30.0) -> Any:
    """Run ``work`` on another thread while the GUI's event loop keeps running; its result.

    Starting or stopping a server takes a second or more: done here on the test's (the
    GUI's) thread it would stall the very loop the test measures.
    """
    result: list[Any] = []
    errors: list[BaseException] = []

    def run() -> None:
        try:
            result.append(work())
        except BaseException as error:  # handed to the test thread below
            errors.append(error)

    thread = threading.Thread(target=run)
    thread.start()
    wait_until(lambda: not thread.is_alive(), timeout, "the background work")
    thread.join()
    if errors:
        raise errors[0]
    return result[0]


def no_traceback(window: Window) -> None:
    texts = window.w.messages.messages()
    assert not [t for t in texts if "Traceback" in t or 'File "' in t], texts


def test_server_gone_then_back(start_server: StartServer, windows: Any) -> None:
    server: ServerProcess = start_server()
    window = windows()
    shown(window)
    window.add("drone", "take_off")
    wait_until(lambda: window.ids("drone"), 30, "take_off shown")
    old = window.ids("drone")

    meanwhile(server.stop)
    wait_until(lambda: window.w.banner.isVisibleTo(window.w), 60, "the banner")
    assert "does not answer" in window.w.banner.text()
    # The operator goes on: adds, deletes, starts. Each ends as a sentence.
    window.add("drone", "land")
    window.click_row("drone", 0)
    QTest.keyClick(window.w.tasks.table_of(old[0]), Qt.Key_Delete)
    window.w.do(Action.DELETE)
    window.said("Could not add land to drone: the mission server did not answer")
    window.said("Could not delete 'take_off'")
    no_traceback(window)
    assert window.ids("drone") == old  # the last known mission stays in view

    # A new server (a fresh mission): the view follows it.
    meanwhile(lambda: start_server("second"))
    added = meanwhile(lambda: add_skill("science_rover", "explore"))
    wait_until(lambda: window.ids("science_rover") == [added], 60, "the new mission shown")
    assert window.ids("drone") == []
    wait_until(lambda: not window.w.banner.isVisibleTo(window.w), 60, "the banner gone")
    window.said("Connected to the mission server")


def test_a_frozen_server_does_not_freeze_the_window(
    start_server: StartServer, windows: Any
) -> None:
    calls = ("add take_off to drone", "add explore to science_rover")
    server = start_server()
    window = windows(timeout=120.0)  # its calls wait for the server, however long it hangs
    shown(window)
    beat = Heartbeat()
    os.kill(server.pid, signal.SIGSTOP)  # the server hangs (as a swapping or stuck host)
    try:
        window.add("drone", "take_off")
        window.add("science_rover", "explore")
        ticked = beat.ticks
        # The operator waits, scrolls, clicks: the loop runs on while both calls wait.
        wait_until(lambda: beat.ticks >= ticked + 20, 60, "twenty ticks of the event loop")
        window.w.tasks.columns["drone"].blueprint_table.viewport().update()
        answers = [m for m in window.w.messages.messages() if any(c in m for c in calls)]
        assert answers == [], "an answer from a frozen server"
    finally:
        os.kill(server.pid, signal.SIGCONT)
        beat.stop()
    # The calls were waiting, not lost: the thawed server answers both.
    for what in calls:
        message = window.said(what, timeout=60)
        assert "Done: " in message, message
    wait_until(lambda: window.w.view.loaded, 60, "still following")
    added = meanwhile(lambda: add_skill("drone", "land"))
    wait_until(lambda: added in window.ids("drone"), 60, "a later change shown")
    no_traceback(window)


def test_two_windows_stay_consistent_and_a_stale_edit_is_a_conflict(
    start_server: StartServer, windows: Any
) -> None:
    start_server()
    first, second = windows(), windows()
    shown(first)
    shown(second)
    first.add("drone", "take_off")
    first.add("drone", "land")
    wait_until(lambda: len(second.ids("drone")) == 2, 30, "the second window sees the adds")
    take_off, land = first.ids("drone")
    assert second.ids("drone") == [take_off, land]

    second.click_row("drone", 0)
    assert second.w.tasks.selected_ids == [take_off]
    before = second.w.view.revision
    # The first operator moves the skills while the second window has not heard yet
    # (nothing runs the second window's event loop in between).
    client = MissionClient(5.0)
    try:
        client.reorder_skills("drone", [land, take_off], base_revision=before)
    finally:
        client.close()
    assert second.w.view.revision == before
    QTest.mouseClick(second.w.control.buttons["move_down"], Qt.LeftButton)
    message = second.said("someone else changed the mission first")
    assert "The view was refreshed" in message
    wait_until(lambda: second.ids("drone") == [land, take_off], 30, "the refreshed view")
    wait_until(lambda: first.ids("drone") == [land, take_off], 30, "the first window too")
    no_traceback(second)

    # The lost-link policy goes through the client's typed call (the server keeps it for
    # the robot, which is not running here).
    column = first.w.tasks.columns["drone"]
    column.ask_policy = lambda *_: LostLinkPolicy(LostLinkKind.HOLD, 30.0)
    QTest.mouseClick(column.policy_button, Qt.LeftButton)
    message = first.said("set drone's policy (on link loss: hold after 30 s)")
    assert "Done:" in message, message
    no_traceback(first)


class Questions:
    """Answers the modal questions the window asks (real QMessageBoxes) and keeps their text."""

    def __init__(self, answers: list[QMessageBox.StandardButton]) -> None:
        self.answers = answers
        self.asked: list[str] = []
        self.timer = QTimer()
        self.timer.timeout.connect(self._answer)
        self.timer.start(20)

    def _answer(self) -> None:
        box = QApplication.activeModalWidget()
        if isinstance(box, QMessageBox) and box.isVisible():
            self.asked.append(box.text())
            QTest.mouseClick(box.button(self.answers.pop(0)), Qt.LeftButton)

    def stop(self) -> None:
        self.timer.stop()


def ctrl_click_row(window: Window, agent: str, row: int) -> None:
    table = window.w.tasks.columns[agent].blueprint_table
    rect = table.visualRect(table.section.index(row, 2))
    QTest.mouseClick(table.viewport(), Qt.LeftButton, Qt.ControlModifier, rect.center())


def test_a_two_robot_barrier_plan_goes_out_with_one_click_and_one_question(
    start_server: StartServer, windows: Any
) -> None:
    start_server()
    window = windows()
    shown(window)
    for agent, skill in [("drone", "take_off"), ("drone", "land")] + [
        ("science_rover", "navigate_to")
    ] * 2:
        window.add(agent, skill)
    wait_until(
        lambda: len(window.ids("drone")) == 2 and len(window.ids("science_rover")) == 2,
        30,
        "the four skills",
    )
    for row in (0, 1):  # barriers: the firsts start together, and so do the seconds
        window.click_row("drone", row)
        ctrl_click_row(window, "science_rover", row)
        QTest.mouseClick(window.w.control.buttons["barrier"], Qt.LeftButton)
        window.said("Done: start 'take_off', 'navigate_to' together" if row == 0 else "'land'")
    wait_until(lambda: len(window.w.view.barriers) == 2, 30, "both barriers shown")
    questions = Questions([QMessageBox.No, QMessageBox.Yes])
    try:
        # The drone up to 'land' but the rover only up to its first skill: one question
        # names the barrier that would wait for ever; answered No, nothing is sent.
        window.click_row("drone", 1)
        ctrl_click_row(window, "science_rover", 0)
        QTest.mouseClick(window.w.control.buttons["synchronize"], Qt.LeftButton)
        wait_until(lambda: len(questions.asked) == 1, 30, "the question")
        assert (
            "drone will wait at a barrier for ever unless you also send science_rover's"
            in (questions.asked[0])
        ), questions.asked
        before = window.w.view.revision
        # Send all robots: one question for the team (no robot listed twice), then one change.
        QTest.mouseClick(window.w.control.buttons["send_all"], Qt.LeftButton)
        message = window.said("Done: send the tasks of drone, science_rover")
    finally:
        questions.stop()
    assert len(questions.asked) == 2, questions.asked
    team = questions.asked[1]
    assert "drone: 2 skills, its whole task" in team and "science_rover: 2 skills" in team
    assert "Warnings" not in team, team
    detail = window.w.messages.detail_of(message)
    assert detail == f"mission revision {before + 1}", (message, detail)
    wait_until(
        lambda: all(
            window.w.view.view(agent).editable == () for agent in ("drone", "science_rover")
        ),
        30,
        "both tasks in transfer",
    )
    no_traceback(window)


def test_the_science_score_is_in_view_once_published(
    start_server: StartServer, windows: Any
) -> None:
    start_server()
    window = windows()
    shown(window)
    strip = window.w.science
    assert strip.isVisible() and strip.text() == NO_SCORE
    publisher = rospy.Publisher(SCIENCE_TOPIC, wire.ScienceState, queue_size=1, latch=True)
    try:
        regions = (
            RegionScience("RSS A", 16, 9, 3, 1, 1, "collaborative"),
            RegionScience("RSS B", 30, -16, 3.5, 0.8, 2, ""),
        )
        publisher.publish(science_to_msg(Science(1.1, 2, regions)))
        wait_until(lambda: strip.science is not None, 30, "the science state")
    finally:
        publisher.unregister()
    text = strip.text()
    assert "Science score 1.10" in text and "2 stones delivered" in text, text
    assert "RSS A (16, 9): identified by both rovers, 1 left" in text, text
    assert "RSS B (30, -16): not identified, 2 left" in text, text
    assert "RSS B at (30, -16): not identified, 2 stones left (best 0.8)" in strip.toolTip()


def test_the_site_map_in_force_and_its_sender_are_in_view(
    start_server: StartServer, windows: Any
) -> None:
    start_server()
    window = windows()
    shown(window)
    line = window.w.site
    wait_until(lambda: line.text() == NO_SITE, 10, "no map in force yet")
    assert line.isVisible()
    publisher = rospy.Publisher(SITE_TOPIC, wire.SiteMap, queue_size=1, latch=True)
    try:
        rock = Footprint("rock", Shape.CYLINDER, 9.0, 6.0, radius=1.6)
        publisher.publish(site_to_msg(SiteModel("quarry", (-40, 40, -40, 40), (rock,)), 0.0))
        wait_until(lambda: line.source is not None, 10, "the map in force")
    finally:
        publisher.unregister()
    assert line.text().startswith(f"site 'quarry' from {rospy.get_name()} at "), line.text()
    assert line.text().endswith(": 1 obstacles, 0 ground robots"), line.text()


def test_save_to_a_local_file_and_open_it_again(
    start_server: StartServer, windows: Any, tmp_path: Path
) -> None:
    start_server()
    window = windows()
    shown(window)
    window.add("drone", "take_off")
    wait_until(lambda: window.ids("drone"), 30, "take_off shown")
    path = tmp_path / "plan.yaml"

    # Save as… through the real dialog (Qt's own, so it can be driven offscreen).
    answer_file_dialog(str(path))
    window.w.actions_.file["save_as"].trigger()
    window.said(f"Saved the mission to {path}")
    assert "take_off" in path.read_text()
    assert not window.w.files.dirty

    window.add("drone", "land")
    wait_until(lambda: len(window.ids("drone")) == 2, 30, "land shown")
    assert window.w.files.dirty
    window.w.files.ask = lambda doing: "discard"  # the unsaved-changes question
    answer_file_dialog(str(path))
    window.w.actions_.file["open"].trigger()
    wait_until(lambda: len(window.ids("drone")) == 1, 30, "the saved mission back")
    assert [s.skill for s in window.w.view.view("drone").skills] == ["take_off"]
    wait_until(lambda: not window.w.files.dirty, 30, "the opened file counts as saved")
    no_traceback(window)


def add_skill(agent: str, skill: str) -> str:
    """Another operator (a plain client) adds a skill; its id."""
    client = MissionClient(5.0)
    try:
        return client.add_skill(agent, skill).skill_id
    finally:
        client.close()


def answer_file_dialog(path: str, timeout: float = 20.0) -> None:
    """Type ``path`` into the next file dialog and press its Save / Open button.

    A dialog that cannot be answered within ``timeout`` is cancelled, so the test fails
    on its assertions instead of waiting in the dialog's own event loop for ever (where
    pytest's timeout cannot reach it).
    """
    deadline = time.monotonic() + timeout

    def choose() -> None:
        dialogs = [
            w
            for w in QApplication.topLevelWidgets()
            if isinstance(w, QFileDialog) and w.isVisible()
        ]
        if time.monotonic() > deadline:
            for dialog in dialogs:
                dialog.reject()
            return
        if not dialogs:
            QTimer.singleShot(20, choose)
            return
        dialog = dialogs[0]
        dialog.findChild(QLineEdit, "fileNameEdit").setText(path)  # as the operator types it
        buttons = dialog.findChild(QDialogButtonBox)
        accept = next(b for b in buttons.buttons() if buttons.buttonRole(b) == buttons.AcceptRole)
        if not accept.isEnabled():  # the dialog is still reading the folder
            QTimer.singleShot(20, choose)
            return
        accept.click()

    QTimer.singleShot(20, choose)


def test_a_send_to_a_robot_out_of_contact_is_shown_waiting(
    start_server: StartServer, windows: Any
) -> None:
    start_server()  # no robot runs: none has been heard
    window = windows()
    shown(window)
    window.add("drone", "take_off")
    wait_until(lambda: window.ids("drone"), 30, "take_off shown")
    column = window.w.tasks.columns["drone"]
    send = column.buttons[RobotAction.SYNC_ALL]
    wait_until(send.isEnabled, 30, "Send to robot enabled")
    questions = Questions([QMessageBox.Yes])  # the question before a whole task goes
    try:
        QTest.mouseClick(send, Qt.LeftButton)
    finally:
        questions.stop()
    assert len(questions.asked) == 1 and "drone: 1 skill, its whole task" in questions.asked[0]
    window.said("queued for drone: not heard since the server started")
    model = column.blueprint_model
    wait_until(
        lambda: model.data(model.index(0, STATUS)) == "waiting for contact",
        30,
        "the row to say the send waits for contact",
    )
    # The send, and the library's default lost-link policy the robot gets when it links: the
    # header may say "1 command" (the policy alone) until the send reaches the view.
    wait_until(
        lambda: "never heard · 2 commands waiting for contact" in column.status_label.text(),
        30,
        "the header to say both commands wait",
    )
    no_traceback(window)
