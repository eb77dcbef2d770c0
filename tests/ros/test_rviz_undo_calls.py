"""rviz's Undo and Redo calls (rosmc_rviz_markers/ros/undo_calls.py) follow the shared rule.

Each undo goes to the client worker against the revision rviz shows; a conflict keeps the
entry for another try, a refusal drops it; several edits in one entry go back one after
the other. The worker is stood in for by one that keeps each call for the test to answer
as the server would. No ROS master.
"""

from __future__ import annotations

from concurrent.futures import Future
from types import SimpleNamespace
from typing import Any

from rosmc_rviz_markers.ros.undo_calls import UndoCalls
from rosmc_server.core import RuleViolation
from rosmc_server.core.live.edit_history import EditHistory, EditKind, Entry
from rosmc_server.ros.client import Outcome, RevisionConflict


class Worker:
    """Keeps each submitted call; :meth:`answer` ends the oldest as the server would."""

    def __init__(self) -> None:
        self.calls: list[tuple[Any, Any, int | None]] = []

    def submit(self, call: Any, done: Any, seen: int | None) -> Future[Any]:
        self.calls.append((call, done, seen))
        future: Future[Any] = Future()
        future.set_result(None)
        return future

    def undone_revision(self) -> int:
        """The revision the oldest waiting call asks to undo."""
        asked: list[int] = []
        self.calls[0][0](SimpleNamespace(undo_edit=asked.append))
        return asked[0]

    def answer(self, outcome: Outcome[Any]) -> None:
        _, done, _ = self.calls.pop(0)
        done(outcome)


def accepted(revision: int) -> Outcome[Any]:
    return Outcome(value=SimpleNamespace(revision=revision))


def test_an_undo_is_made_against_the_revision_shown_and_kept_on_a_conflict() -> None:
    history, worker, shown = EditHistory(), Worker(), [12]
    undo = UndoCalls(history, worker, lambda: shown[0])  # type: ignore[arg-type]
    history.done(EditKind.MOVE_MARKER, 12, "move 'Pose 1'")
    undo.ask(redo=False)
    assert worker.undone_revision() == 12 and worker.calls[0][2] == 12
    undo.ask(redo=False)  # one at a time: nothing more is sent
    assert len(worker.calls) == 1
    worker.answer(Outcome(error=RevisionConflict("someone changed it", 12, 13)))
    assert history.next_undo() == Entry((12,), "move 'Pose 1'")  # kept

    shown[0] = 13
    undo.ask(redo=False)
    assert worker.calls[0][2] == 13
    worker.answer(accepted(14))
    assert history.next_undo() is None and history.next_redo() == Entry((14,), "move 'Pose 1'")

    undo.ask(redo=True)
    assert worker.undone_revision() == 14
    worker.answer(Outcome(error=RuleViolation("task marker 'Pose 1' was changed since 14")))
    assert history.next_redo() is None and history.next_undo() is None  # dropped


def test_joined_edits_go_back_one_after_the_other() -> None:
    history, worker = EditHistory(), Worker()
    undo = UndoCalls(history, worker, lambda: 7)  # type: ignore[arg-type]
    for revision in (5, 6, 7):
        history.done(EditKind.ADD_SKILL, revision, "copy")
    history.join([5, 6, 7], "duplicate 3 skills")
    undo.ask(redo=False)
    backs = []
    for answer in (8, 9, 10):
        backs.append(worker.undone_revision())
        worker.answer(accepted(answer))
    assert backs == [7, 6, 5] and not worker.calls
    assert history.next_redo() == Entry((10, 9, 8), "duplicate 3 skills")
