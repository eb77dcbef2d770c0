"""Which buttons the operator can press, for each selection, status and section.

The widget's actions are checked after real clicks on rows of a real mission (so the
enabling path is the one the operator sees); robot actions per executor state.
"""

from __future__ import annotations

from collections.abc import Iterator, Sequence

import pytest
from python_qt_binding.QtCore import Qt
from python_qt_binding.QtTest import QTest

from rosmc_rqt_command.core.legality import RobotAction, RobotLegality, legal_robot_actions
from rosmc_rqt_command.qt.policy_dialog import PolicyDialog
from rosmc_server.core import (
    AgentStatus,
    InvalidRequest,
    Library,
    LostLinkKind,
    LostLinkPolicy,
    Mission,
    SkillStatus,
)
from tests.unit.test_command_harness import Gui, open_gui, qt_app

S = SkillStatus
R = RobotAction


@pytest.fixture
def gui(mission: Mission, library: Library) -> Iterator[Gui]:
    """A command widget following the ``mission`` fixture."""
    yield from open_gui(mission, library)


def test_nothing_selected_nothing_to_do(gui: Gui) -> None:
    gui.feed.add("alpha")
    assert gui.enabled() == set()


@pytest.mark.parametrize(
    ("row", "expected"),
    [
        (0, {"delete", "synchronize", "move_down"}),
        (1, {"delete", "synchronize", "move_up", "move_down"}),
        (2, {"delete", "synchronize", "move_up"}),
    ],
)
def test_a_planned_skill_can_be_deleted_sent_and_moved(
    gui: Gui, row: int, expected: set[str]
) -> None:
    for _ in range(3):
        gui.feed.add("alpha")
    gui.click_row("alpha", True, row)
    assert gui.enabled() == expected


def test_planned_skills_of_two_robots_can_start_together(gui: Gui) -> None:
    gui.feed.add("alpha")
    gui.feed.add("bravo")
    gui.click_row("alpha", True, 0)
    gui.click_row("bravo", True, 0, Qt.ControlModifier)
    # "Send" sends both robots up to their selected skill (one team send); "move" acts on
    # one robot's task.
    assert gui.enabled() == {"delete", "barrier", "synchronize"}


def test_two_skills_of_one_robot_cannot_start_together(gui: Gui) -> None:
    gui.feed.add("alpha")
    gui.feed.add("alpha")
    gui.click_row("alpha", True, 0)
    gui.click_row("alpha", True, 1, Qt.ControlModifier)
    assert gui.enabled() == {"delete", "synchronize"}


def test_a_barrier_member_offers_removal_until_it_starts(gui: Gui) -> None:
    feed = gui.feed
    first, partner = feed.add("alpha", "wait"), feed.add("bravo", "wait")
    feed("add_barrier", [first, partner])
    gui.click_row("alpha", True, 0)
    assert "delete_barrier" in gui.enabled()
    assert "barrier" not in gui.enabled()
    feed.sync("alpha")
    feed.sync("bravo")
    gui.click_row("alpha", False, 0)
    assert gui.enabled() == {"unsynchronize", "delete_barrier"}
    feed("report_status", first, S.SYNCWAITING)
    assert gui.enabled() == set()  # started: the barrier holds, nothing to take back


def test_uploading_and_removing_skills_are_pending(gui: Gui) -> None:
    feed = gui.feed
    skill = feed.add("alpha")
    feed.sync("alpha", confirm=False)
    gui.click_row("alpha", True, 0)
    # Uploading: not editable, but the robot has not confirmed it, so Take back (which the
    # server turns into cancelling the upload) is offered, as the server accepts it.
    assert gui.enabled() == {"unsynchronize"}
    feed("confirm_synchronized", "alpha", [skill])
    assert gui.enabled() == {"unsynchronize"}
    feed("unsynchronize", "alpha", skill)
    assert gui.enabled() == set()  # removing: wait for the robot


def test_running_paused_and_done_skills_offer_nothing(gui: Gui) -> None:
    feed = gui.feed
    skill = feed.add("alpha")
    feed.sync("alpha")
    gui.click_row("alpha", False, 0)
    for status in (S.RUNNING, S.PAUSED, S.RUNNING, S.SUCCESS):
        feed("report_status", skill, status)
        assert gui.enabled() == set(), status


def test_a_failure_can_be_retried_or_skipped_once(gui: Gui) -> None:
    feed = gui.feed
    skill = feed.add("alpha")
    feed.sync("alpha")
    feed("report_status", skill, S.RUNNING)
    feed("report_status", skill, S.FAILURE, text="wheel stuck")
    gui.click_row("alpha", False, 0)
    assert gui.enabled() == {"retry", "skip"}
    feed("retry", skill)
    assert gui.enabled() == set()


def test_read_only_window_enables_nothing(mission: Mission, library: Library) -> None:
    harness = Gui(mission, library, read_only=True)
    try:
        harness.feed.add("alpha")
        harness.click_row("alpha", True, 0)
        assert harness.enabled() == set()
        column = harness.widget.tasks.columns["alpha"]
        assert not any(button.isEnabled() for button in column.buttons.values())
        assert not column.add_button.isEnabled()
        harness.widget.do_robot("alpha", R.SYNC_ALL)
        assert harness.backend.requests == []
    finally:
        harness.close()


def test_robot_buttons_follow_the_robot(gui: Gui) -> None:
    feed = gui.feed
    column = gui.widget.tasks.columns["alpha"]

    def enabled() -> set[RobotAction]:
        gui.widget.repaints.show_statuses_now()  # the 5 Hz header repaint, now
        return {action for action, button in column.buttons.items() if button.isEnabled()}

    assert enabled() == set()
    skill = feed.add("alpha", "wait")
    assert enabled() == {R.SYNC_ALL}
    feed.sync("alpha")
    assert enabled() == {R.START}
    feed.statuses(AgentStatus("alpha", link="up", executor_state="running"))
    feed("report_status", skill, S.RUNNING)
    assert enabled() == {R.PAUSE, R.STOP}
    feed.statuses(AgentStatus("alpha", link="up", executor_state="paused"))
    feed("report_status", skill, S.PAUSED)
    assert enabled() == {R.RESUME, R.STOP}
    # The all-robot actions cover every robot.
    start_all = gui.widget.actions_.all_robots[R.RESUME]
    assert start_all.isEnabled()
    assert not gui.widget.actions_.all_robots[R.START].isEnabled()


def test_robot_legality_is_recomputed_only_for_touched_robots(gui: Gui) -> None:
    feed = gui.feed
    feed.add("alpha")
    cache = RobotLegality()
    cache.update(gui.widget.view)
    assert cache.of("alpha") == {R.SYNC_ALL} and cache.of("bravo") == set()
    feed.add("bravo")
    assert cache.of("bravo") == set()  # not told yet
    cache.update(gui.widget.view, ["bravo"])
    assert cache.of("bravo") == legal_robot_actions(gui.widget.view, "bravo") == {R.SYNC_ALL}
    assert cache.any() == {R.SYNC_ALL}


def test_the_lost_link_policy_is_chosen_among_the_robots_skills(gui: Gui) -> None:
    column = gui.widget.tasks.columns["alpha"]
    assert column.policy_button.isEnabled()
    offered: list[list[str]] = []

    def ask(agent: str, skills: Sequence[str], parent: object, *_: object) -> LostLinkPolicy | None:
        offered.append(list(skills))
        dialog = PolicyDialog(agent, skills, preferred="wait")
        dialog.set_kind(LostLinkKind.SAFE_SKILL)
        dialog.after_spin.setValue(45)
        return dialog.policy()

    column.ask_policy = ask
    QTest.mouseClick(column.policy_button, Qt.LeftButton)
    assert offered == [["move", "noop", "scan", "wait"]]
    [request] = gui.backend.requests
    assert request.operation == "set_lost_link_policy"
    assert request.args == ("alpha", LostLinkPolicy(LostLinkKind.SAFE_SKILL, 45.0, "wait"))
    assert "run wait after 45 s" in request.what
    column.ask_policy = lambda *_: None  # the operator cancels
    QTest.mouseClick(column.policy_button, Qt.LeftButton)
    assert len(gui.backend.requests) == 1


def test_the_policy_dialog_offers_each_kind() -> None:
    app = qt_app()  # kept alive for the whole test
    dialog = PolicyDialog("alpha", [])
    assert dialog.policy() == LostLinkPolicy()  # keep going
    assert not dialog.after_spin.isEnabled()
    dialog.set_kind(LostLinkKind.HOLD)
    dialog.after_spin.setValue(30)
    assert dialog.after_spin.isEnabled() and not dialog.skill_combo.isEnabled()
    assert dialog.policy() == LostLinkPolicy(LostLinkKind.HOLD, 30.0)
    dialog.set_kind(LostLinkKind.SAFE_SKILL)  # this robot has no skill to run
    with pytest.raises(InvalidRequest, match="no skill"):
        dialog.policy()
    dialog.buttons.button(dialog.buttons.Ok).click()
    assert dialog.problem.text() == "this robot has no skill to run as its safe skill."
    assert dialog.result() != dialog.Accepted
    app.processEvents()
