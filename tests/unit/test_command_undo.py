"""The command window's Undo and Redo over the shared edit history, in the real widget.

The operator deletes a skill with the mouse; the request says it is an edit
(``EditKind.DELETE_SKILLS``), so Edit > Undo takes it back. The undo is made against the
revision shown; answered as a conflict it stays (the message says so and Undo is offered
again), refused by the mission rules it goes, with the server's sentence. A request that
is not an edit (a synchronize) leaves the history alone. Offscreen Qt, no ROS: the
answers are the ones the server would give.
"""

from __future__ import annotations

import os
from collections.abc import Iterator
from types import SimpleNamespace

import pytest

from rosmc_rqt_command.core.legality import Action
from rosmc_rqt_command.core.requests import Answer, Request
from rosmc_server.core import Library, Mission
from rosmc_server.core.live.edit_history import EditKind
from tests.unit.test_command_harness import Gui, open_gui

SCREENSHOT = os.environ.get("ROSMC_UNDO_SCREENSHOT", "")


@pytest.fixture
def gui(mission: Mission, library: Library) -> Iterator[Gui]:
    yield from open_gui(mission, library)


def last_request(gui: Gui) -> Request:
    return gui.backend.requests[-1]


def delete_first(gui: Gui, agent: str) -> tuple[str, Request]:
    """Delete the robot's first blueprint skill with the mouse; the skill and the request."""
    skill = gui.ids(agent, True)[0]
    gui.click_row(agent, True, 0)
    gui.widget.do(Action.DELETE)
    return skill, last_request(gui)


def test_undo_kept_on_a_conflict_and_dropped_on_a_refusal(gui: Gui) -> None:
    gui.feed.add("alpha", "move", label="go")
    skill, request = delete_first(gui, "alpha")
    assert request.kind is EditKind.DELETE_SKILLS
    event = gui.feed("delete_skills", [skill])  # the server accepts it
    gui.widget.on_answer(Answer(request, value=SimpleNamespace(revision=event.revision)))
    undo = gui.widget.history.undo_action
    assert undo.isEnabled() and undo.text() == "&Undo delete 'go'"

    undo.trigger()
    sent = last_request(gui)
    assert (sent.operation, sent.args) == ("undo_edit", (event.revision,))
    assert sent.seen == gui.widget.view.revision and not undo.isEnabled()  # one at a time
    gui.widget.on_answer(Answer(sent, error="revision 2 is stale", conflict=True))
    assert undo.isEnabled() and undo.text() == "&Undo delete 'go'"
    said = [m for m in gui.widget.messages.messages() if "Could not undo delete 'go'" in m]
    assert len(said) == 1, said  # once, by the message area, not again by the history
    assert "someone else changed the mission first (revision 2 is stale)" in said[0]
    assert "try again" in said[0]
    if SCREENSHOT:
        gui.widget.grab().save(SCREENSHOT)

    undo.trigger()
    again = last_request(gui)
    assert again is not sent and again.args == (event.revision,)
    reason = "skill 'alpha-1' was changed since revision 2; undo that change first"
    gui.widget.on_answer(Answer(again, error=reason))
    assert not undo.isEnabled() and undo.text() == "&Undo"
    assert reason in gui.widget.messages.messages()[0]


def test_a_request_that_is_not_an_edit_is_not_undoable(gui: Gui) -> None:
    first = gui.feed.add("bravo", "wait")
    gui.click_row("bravo", True, 0)
    gui.widget.do(Action.SYNC)
    request = last_request(gui)
    assert request.operation == "synchronize" and request.kind is None
    event = gui.feed("synchronize", "bravo", first)
    gui.widget.on_answer(Answer(request, value=SimpleNamespace(revision=event.revision)))
    assert not gui.widget.history.undo_action.isEnabled()
    assert "Ctrl+Z" not in gui.widget.messages.messages()[0]
