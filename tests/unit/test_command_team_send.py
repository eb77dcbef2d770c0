"""Sending several robots' tasks at once from the command widget: one question, one request."""

from __future__ import annotations

from collections.abc import Iterator

import pytest
from python_qt_binding.QtCore import Qt
from python_qt_binding.QtTest import QTest

from rosmc_server.core import Library, Mission
from tests.unit.test_command_harness import Gui, open_gui


@pytest.fixture
def gui(mission: Mission, library: Library) -> Iterator[Gui]:
    """A command widget following the ``mission`` fixture."""
    yield from open_gui(mission, library)


def two_barriers(gui: Gui) -> tuple[list[str], list[str]]:
    """alpha and bravo with two skills each; barriers between the firsts and the seconds."""
    feed = gui.feed
    alpha = [feed.add("alpha", "wait"), feed.add("alpha", "wait")]
    bravo = [feed.add("bravo", "wait"), feed.add("bravo", "wait")]
    feed("add_barrier", [alpha[0], bravo[0]])
    feed("add_barrier", [alpha[1], bravo[1]])
    return alpha, bravo


def test_send_all_robots_asks_once_and_sends_every_plan_in_one_request(gui: Gui) -> None:
    two_barriers(gui)
    asked: list[tuple[str, list[str]]] = []
    answers = [False, True]

    def confirm_team(text: str, warnings: list[str]) -> bool:
        asked.append((text, warnings))
        return answers.pop(0)

    gui.widget.dispatcher.confirm_team = confirm_team
    button = gui.widget.control.buttons["send_all"]
    assert button.isEnabled()
    QTest.mouseClick(button, Qt.LeftButton)  # answered No: nothing is sent
    assert gui.backend.requests == []
    QTest.mouseClick(button, Qt.LeftButton)  # answered Yes
    assert len(asked) == 2
    text, warnings = asked[0]
    assert "alpha: 2 skills, its whole task" in text and "bravo: 2 skills" in text, text
    assert warnings == []  # every barrier member goes: nobody waits for ever
    assert gui.backend.operations() == ["synchronize_team"]
    assert gui.backend.requests[0].args == ({"alpha": None, "bravo": None},)


def test_send_up_to_the_selected_skills_lists_every_warning_in_one_question(gui: Gui) -> None:
    alpha, bravo = two_barriers(gui)
    asked: list[list[str]] = []

    def confirm_team(text: str, warnings: list[str]) -> bool:
        asked.append(warnings)
        return True

    gui.widget.dispatcher.confirm_team = confirm_team
    gui.click_row("alpha", True, 1)
    gui.click_row("bravo", True, 0, Qt.ControlModifier)
    assert "synchronize" in gui.enabled()
    QTest.mouseClick(gui.widget.control.buttons["synchronize"], Qt.LeftButton)
    assert asked == [["alpha will wait at a barrier for ever unless you also send bravo's 'wait'."]]
    assert gui.backend.operations() == ["synchronize_team"]
    assert gui.backend.requests[0].args == ({"alpha": alpha[1], "bravo": bravo[0]},)
