"""Nothing is sent to a robot by a slip of the mouse; a held robot, a barrier wait and a robot
out of contact are said in words.

The real widget (offscreen Qt) follows a real mission through the unit harness; the
operator's clicks are real mouse clicks, and the questions are the real message boxes.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from types import SimpleNamespace

import pytest
from python_qt_binding.QtCore import QPoint, Qt, QTimer
from python_qt_binding.QtTest import QTest
from python_qt_binding.QtWidgets import QApplication, QMessageBox

from rosmc_rqt_command.core.holding import lost_link_hold
from rosmc_rqt_command.core.legality import RobotAction
from rosmc_rqt_command.core.phrasing import answer_detail, answer_message
from rosmc_rqt_command.core.presentation import LAST_KNOWN_TEXT_COLOUR, last_known_colour
from rosmc_rqt_command.core.requests import Answer, ask
from rosmc_rqt_command.qt.task_model import STATUS
from rosmc_server.core import (
    AgentStatus,
    Library,
    LostLinkKind,
    LostLinkPolicy,
    LostLinkTrigger,
    Mission,
    PolicyInForce,
    SkillStatus,
)
from rosmc_server.core.model.control import ControlCommand, HoldCause
from rosmc_server.executor.core.lost_link import LostLinkGuard
from tests.team_gui import click, columns, settle, step_right
from tests.team_twenty import stage, twenty_robot_library
from tests.unit.conftest import make_mission
from tests.unit.test_command_harness import Gui, open_gui

HELD_POLICY = PolicyInForce(
    LostLinkPolicy(LostLinkKind.RETURN_TO_LINK, 60.0, "navigate_to", when=LostLinkTrigger.IDLE),
    acted="returning to the last link position (18.9, -1.0) after 68 s without ground contact; "
    "ground contact is back (done); holding",
)


@pytest.fixture
def gui(mission: Mission, library: Library) -> Iterator[Gui]:
    """A command widget following the ``mission`` fixture."""
    yield from open_gui(mission, library)


class Asked:
    """Answers the next real message box with a key or a button, keeping what it said."""

    def __init__(self, answer: Callable[[QMessageBox], None]) -> None:
        self.answer = answer
        self.texts: list[str] = []
        self.defaults: list[str] = []
        self.timer = QTimer()
        self.timer.timeout.connect(self._on_timer_timeout)
        self.timer.start(20)

    def _on_timer_timeout(self) -> None:
        box = QApplication.activeModalWidget()
        if isinstance(box, QMessageBox) and box.isVisible():
            self.texts.append(box.text())
            self.defaults.append(box.defaultButton().text())
            self.answer(box)

    def stop(self) -> None:
        self.timer.stop()


def press_enter(box: QMessageBox) -> None:
    """The operator hits Enter: the default button."""
    QTest.keyClick(box, Qt.Key_Return)


def click_send(box: QMessageBox) -> None:
    """The operator clicks *Send*."""
    QTest.mouseClick(box.button(QMessageBox.Yes), Qt.LeftButton)


def ask_with(answer: Callable[[QMessageBox], None], press: Callable[[], None]) -> Asked:
    """Press something that asks a question and answer it with ``answer``."""
    asked = Asked(answer)
    try:
        press()
    finally:
        asked.stop()
    return asked


def test_a_whole_task_goes_only_after_the_operator_clicks_send(gui: Gui) -> None:
    for skill in ("move", "wait"):
        gui.feed.add("alpha", skill)
    button = gui.widget.tasks.columns["alpha"].buttons[RobotAction.SYNC_ALL]
    assert button.text() == "Send to robot…"
    enter = ask_with(press_enter, lambda: QTest.mouseClick(button, Qt.LeftButton))
    assert enter.defaults == ["Don't send"]
    assert "Send to alpha:\n  • alpha: 2 skills, its whole task" in enter.texts[0]
    assert gui.backend.requests == []  # Enter took the default: nothing was sent
    send = ask_with(click_send, lambda: QTest.mouseClick(button, Qt.LeftButton))
    assert len(send.texts) == 1
    assert gui.backend.operations() == ["synchronize"]
    assert gui.backend.requests[0].args == ("alpha", None)


def test_send_all_robots_defaults_to_not_sending(gui: Gui) -> None:
    gui.feed.add("alpha", "move")
    gui.feed.add("bravo", "wait")
    button = gui.widget.control.buttons["send_all"]
    enter = ask_with(press_enter, lambda: QTest.mouseClick(button, Qt.LeftButton))
    assert enter.defaults == ["Don't send"] and "alpha: 1 skill" in enter.texts[0]
    assert gui.backend.requests == []
    ask_with(click_send, lambda: QTest.mouseClick(button, Qt.LeftButton))
    assert gui.backend.operations() == ["synchronize_team"]


def test_adding_a_skill_keeps_the_task_panel_still_under_the_pointer() -> None:
    library = twenty_robot_library()
    gui = Gui(make_mission(library), library)
    try:
        gui.widget.resize(1600, 1000)
        stage(gui.feed)
        settle(gui.widget)
        click(gui.widget, "team_compact")
        for _ in range(3):
            step_right(gui.widget)
        tasks = gui.widget.tasks
        bar = tasks.horizontalScrollBar()
        viewport = tasks.viewport()
        # The rightmost column whose Add button is on screen, partly cut off at the edge.
        column = max(
            (c for c in columns(gui.widget).values() if c.isVisible()),
            key=lambda c: (
                c.add_button.mapTo(viewport, QPoint(0, 0)).x()
                if c.add_button.mapTo(viewport, QPoint(0, 0)).x() < viewport.width() - 40
                else -1
            ),
        )
        where = column.add_button.mapTo(viewport, QPoint(0, 0))
        scrolled = bar.value()

        def choose_first() -> None:
            menu = column.add_menu
            if menu.isVisible():
                centre = menu.actionGeometry(menu.actions()[0]).center()
                QTest.mouseClick(menu, Qt.LeftButton, Qt.NoModifier, centre)
            else:
                QTimer.singleShot(20, choose_first)

        QTimer.singleShot(20, choose_first)
        QTest.mouseClick(column.add_button, Qt.LeftButton)
        settle(gui.widget)
        request = gui.backend.requests[-1]
        assert request.operation == "add_skill" and request.args[0] == column.agent
        added = gui.feed.add(column.agent, request.args[1])  # the server adds it
        assert request.on_answer is not None
        request.on_answer(Answer(request, value=type("Added", (), {"skill_id": added})()))
        settle(gui.widget)
        assert gui.widget.tasks.selected_ids == [added]
        assert bar.value() == scrolled, "the task panel did not move sideways"
        assert column.add_button.mapTo(viewport, QPoint(0, 0)) == where
    finally:
        gui.close()


def held(gui: Gui) -> tuple[str, str]:
    """alpha holds after its lost-link return, with a barrier member bravo waits for."""
    feed = gui.feed
    member, partner = feed.add("alpha", "wait"), feed.add("bravo", "wait")
    feed("add_barrier", [member, partner])
    feed.sync("alpha")
    feed.sync("bravo")
    feed.statuses(
        AgentStatus(
            "alpha",
            link="up",
            executor_state="paused",
            lost_link=HELD_POLICY,
            hold=HoldCause.RETURN_POINT,
        ),
        AgentStatus("bravo", link="up", last_heard=0.0, executor_state="waiting"),
    )
    settle(gui.widget)
    return member, partner


SENTENCE = "alpha holds at its lost-link return point \u2014 its barrier partners bravo wait."


def test_a_held_robot_and_whom_it_blocks_are_said_with_resume_one_click_away(gui: Gui) -> None:
    held(gui)
    notice = gui.widget.tasks.columns["alpha"].hold_notice
    assert notice.isVisible() and notice.text.text() == SENTENCE
    assert not gui.widget.tasks.columns["bravo"].hold_notice.isVisible()
    gui.widget.repaints.warn_now()
    assert SENTENCE in gui.widget.messages.warnings
    QTest.mouseClick(notice.resume_button, Qt.LeftButton)
    assert gui.backend.operations() == ["control"]
    assert gui.backend.requests[0].args == (ControlCommand.RESUME, "alpha")


def test_the_warnings_area_resumes_a_held_robot_with_one_click(gui: Gui) -> None:
    held(gui)
    gui.widget.repaints.warn_now()
    messages = gui.widget.messages
    assert list(messages.hold_buttons) == ["alpha"]
    button = messages.hold_buttons["alpha"]
    assert button.isVisible() and button.text() == "Resume alpha"
    QTest.mouseClick(button, Qt.LeftButton)
    assert gui.backend.operations() == ["control"]
    assert gui.backend.requests[0].args == (ControlCommand.RESUME, "alpha")
    gui.feed.statuses(AgentStatus("alpha", link="up", executor_state="idle"))
    settle(gui.widget)
    gui.widget.repaints.warn_now()
    assert not messages.hold_bar.isVisible() and not messages.hold_buttons


def test_a_barrier_partner_says_whom_it_waits_for_and_since_when(gui: Gui) -> None:
    _member, partner = held(gui)
    gui.feed("report_status", partner, SkillStatus.SYNCWAITING)
    gui.feed.statuses(
        AgentStatus(
            "bravo",
            link="up",
            executor_state="waiting",
            current_skill=partner,
            barrier_wait=92.0,
        )
    )
    settle(gui.widget)
    label = gui.widget.tasks.columns["bravo"].wait_label
    assert label.isVisible()
    assert label.text() == "bravo waits for alpha at barrier B1 since 1 min 32 s"


def test_sending_work_to_a_held_robot_warns_that_it_will_not_start(gui: Gui) -> None:
    held(gui)
    gui.feed.add("alpha", "move")
    button = gui.widget.tasks.columns["alpha"].buttons[RobotAction.SYNC_ALL]
    asked = ask_with(press_enter, lambda: QTest.mouseClick(button, Qt.LeftButton))
    assert "alpha is holding after its lost-link policy acted" in asked.texts[0]
    assert "until you press Resume alpha" in asked.texts[0]


def test_a_hold_is_read_from_the_typed_field_not_from_the_policy_words(gui: Gui) -> None:
    now = [100.0]
    guard = LostLinkGuard("alpha", lambda: now[0], {})
    guard.adopt(LostLinkPolicy(LostLinkKind.HOLD, 5.0), default=False)
    now[0] += 10.0
    guard.trigger(True, lambda _note: None)
    guard.contact()
    assert guard.held is HoldCause.LOST_LINK
    in_force = guard.in_force()
    gui.feed.statuses(
        AgentStatus(
            "alpha", link="up", executor_state="paused", lost_link=in_force, hold=guard.held
        )
    )
    settle(gui.widget)
    hold = lost_link_hold(gui.widget.view, "alpha")
    assert hold is not None and hold.link_back and hold.partners == ()
    assert hold.sentence() == "alpha holds where it lost the link."
    # The same policy in force without the field: not a hold (what it did is not read).
    gui.feed.statuses(AgentStatus("alpha", link="up", executor_state="paused", lost_link=in_force))
    settle(gui.widget)
    assert lost_link_hold(gui.widget.view, "alpha") is None


def test_rows_of_a_robot_out_of_contact_read_last_known_with_their_age(gui: Gui) -> None:
    gui.feed.add("alpha", "move")
    (running,) = gui.feed.sync("alpha")
    gui.feed("report_status", running, SkillStatus.RUNNING)
    gui.feed.statuses(AgentStatus("alpha", link="up", last_heard=0.0))
    settle(gui.widget)
    model = gui.widget.tasks.columns["alpha"].synced_model
    cell = model.index(0, STATUS)
    assert model.data(cell) == "running"
    current = model.data(cell, Qt.BackgroundRole).color().name()
    gui.feed.statuses(AgentStatus("alpha", link="down", last_heard=40.0))
    settle(gui.widget)
    assert model.data(cell) == "running (last known, 40 s ago)"
    greyed = model.data(cell, Qt.BackgroundRole).color().name()
    assert greyed != current and greyed == last_known_colour(current)
    assert model.data(cell, Qt.ForegroundRole).color().name() == LAST_KNOWN_TEXT_COLOUR
    assert model.data(cell, Qt.FontRole).italic()
    gui.feed.statuses(AgentStatus("alpha", link="down", last_heard=95.0))
    settle(gui.widget)
    assert model.data(cell) == "running (last known, 1 min ago)"
    gui.feed.statuses(AgentStatus("alpha", link="up", last_heard=0.0))
    settle(gui.widget)
    assert model.data(cell) == "running"
    assert model.data(cell, Qt.BackgroundRole).color().name() == current


def test_answers_are_said_without_the_revision_which_stays_in_the_tooltip(gui: Gui) -> None:
    request = ask(lambda c: c.delete_skills, "delete 'go'")(["s1"])
    answer = Answer(request, SimpleNamespace(revision=626))
    assert answer_message(answer, "Ctrl+Z undoes it") == (
        "Done: delete 'go' (Ctrl+Z undoes it).",
        "ok",
    )
    assert answer_detail(answer) == "mission revision 626"
    assert answer_detail(Answer(request, error="no such skill")) == ""
    gui.widget.messages.say(*answer_message(answer), answer_detail(answer))
    item = gui.widget.messages.log.item(0)
    assert "626" not in item.text() and item.toolTip() == "mission revision 626"


def test_the_status_cell_names_the_barrier_by_its_tag(gui: Gui) -> None:
    _member, partner = held(gui)
    gui.feed("report_status", partner, SkillStatus.SYNCWAITING)
    barrier_id = gui.feed.mission.state.barriers[0].id
    gui.feed.statuses(
        AgentStatus("bravo", link="up", current_skill=partner, waiting_on=f"alpha at {barrier_id}")
    )
    settle(gui.widget)
    model = gui.widget.tasks.columns["bravo"].synced_model
    assert model.data(model.index(0, STATUS)) == "waiting on alpha at B1"


def test_a_replay_says_a_hold_but_offers_no_resume(mission: Mission, library: Library) -> None:
    replay = Gui(mission, library, read_only=True)
    try:
        held(replay)
        replay.widget.repaints.warn_now()
        notice = replay.widget.tasks.columns["alpha"].hold_notice
        assert notice.isVisible() and not notice.resume_button.isEnabled()
        assert not replay.widget.messages.hold_buttons["alpha"].isEnabled()
    finally:
        replay.close()
